"""The search's evaluation of a candidate: its metrics on the search grid in one compiled pass.

The straightforward path (:func:`~reflector_opt.optimiser._evaluation.evaluate`) builds a
:class:`~reflector_opt.design._design.Design`, runs the forward model on the five-point stencil
of the grid and judges the result with the array functions of :mod:`reflector_opt.analysis`.
:class:`FusedObjective` computes the same quantities from the design variables directly:

1. the geometry of the candidate (:func:`~reflector_opt.optimiser._variables.placement`) and,
   in one compiled pass each, the sphere centre in the sensor frames at the Chebyshev points of
   the workspace (:func:`reflector_opt.model._kernel.pose_geometry`) and the Eq-3 and axial
   distances on the search grid;
2. the radiometric coupling at those points (:func:`reflector_opt.model._optics.surface_couplings`,
   mirror and Lambertian parts once, combined for every specular fraction of the problem). In
   the mirror-symmetric layout (the default: the pair straddles the xz-plane) the second
   sensor sees, at pose (γ, α), what the first sees at (γ, −α) with the frame's w mirrored,
   and the coupling is even in w, so only the first sensor's coupling is computed and the
   second's interpolant follows by negating the odd roll terms;
3. the Chebyshev interpolant and its exact pitch and roll derivatives on the grid, the output
   voltages on the central-difference stencil in coupling space (the electronics' clamp is
   differenced as in :func:`~reflector_opt.analysis._jacobian.jacobian_from_stencil`);
4. :func:`judge_poses`, one compiled pass over the grid: Cramér–Rao resolution, condition
   number, fold (det J sign) and the first-order local estimate of uniqueness; the voltage
   separation of poses ≥ 1° apart by the exact sweep of
   :func:`~reflector_opt.analysis._resolution.min_separation_sigma`;
5. the constraints of :mod:`~reflector_opt.optimiser._constraints` from these values, with the
   same limits, scales and penalty as the straightforward path;
6. in operating conditions, or with a drift limit, what the fused pass does not compute:
   :func:`~reflector_opt.optimiser._evaluation.in_conditions` builds the candidate's design
   and adds the drift constraint and, for a feasible candidate only (an infeasible one's
   score does not read the objective), the error budget's objective (about 15 ms, five
   times the fused pass, most of it the budget's joint-play term).

The interpolant spans the same box as the straightforward path's (the workspace widened by
the stencil's step, 8 × 8 points over ±15.01°); the two differ only by the derivative taken
from the interpolant instead of differences of it (benchmarks/bench_optimise.py prints the
largest difference over a sample of candidates). The returned design is always re-evaluated by the
straightforward path on the 0.1° grid.
"""

import math
from typing import NamedTuple

import numba
import numpy as np
from numpy.polynomial import chebyshev

from reflector_opt.analysis._jacobian import JACOBIAN_STEP_DEG, jacobian_from_stencil
from reflector_opt.analysis._metrics import (
    DesignMetrics,
    distance_window,
    reflector_reach_mm,
    shell_wall_mm,
)
from reflector_opt.analysis._resolution import (
    UNIQUENESS_POSE_SEPARATION_DEG,
    min_separation_sigma,
)
from reflector_opt.model import _kernel as kernel
from reflector_opt.model._geometry import pose_trig, rotate_centre, sensor_frames
from reflector_opt.model._interpolation import PoseBox, fit_coefficients
from reflector_opt.model._operating import readings
from reflector_opt.model._optics import surface_couplings
from reflector_opt.model._surface import SurfaceCoupling
from reflector_opt.optimiser._constraints import worst_case_constraints
from reflector_opt.optimiser._evaluation import (
    Evaluation,
    PenalisedObjective,
    in_conditions,
    objective_value,
)
from reflector_opt.optimiser._variables import placement

#: Detector direction of every candidate's sensors (the strip is vertical).
_DETECTOR = (0.0, 0.0, 1.0)


#: Compiled like the forward kernel (on-disk cache where possible, numpy error model).
@numba.njit(**kernel._OPTIONS)
def judge_poses(jac, sigma_v, separation_deg, res_pitch, res_roll, cond):
    """Resolution, conditioning, fold and local uniqueness over a pose grid, in one pass.

    With JᵀJ = [[a, b], [b, c]] at each pose: the Cramér–Rao 1σ resolution
    ``σ_γ = σ_V·sqrt(c/(ac − b²))``, ``σ_α = σ_V·sqrt(a/(ac − b²))`` (Kay 1993, ch. 3), the
    condition number ``sqrt(λ_max/λ_min)`` (inf where J is singular), the sign of det J for
    two outputs, and the first-order voltage separation of poses ``separation_deg`` apart,
    ``separation·sqrt(λ_min)/σ_V`` at the least sensitive pose. The same formulas as
    :mod:`reflector_opt.analysis._resolution`, which tests/optimise/test_fused_objective.py
    compares.

    Parameters
    ----------
    jac : numpy.ndarray, shape (N, S, 2)
        ∂V/∂(γ, α) at each pose, V/deg.
    sigma_v : float
        RMS voltage noise, V.
    separation_deg : float
        Pose separation of the uniqueness check, degrees.
    res_pitch, res_roll, cond : numpy.ndarray, shape (N,)
        Receive σ_γ and σ_α (degrees) and the condition number.

    Returns
    -------
    (int, float, float)
        Prevailing sign of det J (0 for more than two outputs or J zero everywhere), the
        fraction of poses off it, and the first-order separation in σ_V.
    """
    n, outputs = jac.shape[0], jac.shape[1]
    n_pos, n_neg, lam_floor = 0, 0, np.inf
    for i in range(n):
        a, b, c = 0.0, 0.0, 0.0
        for k in range(outputs):
            a += jac[i, k, 0] * jac[i, k, 0]
            b += jac[i, k, 0] * jac[i, k, 1]
            c += jac[i, k, 1] * jac[i, k, 1]
        lam_max = 0.5 * (a + c) + math.hypot(0.5 * (a - c), b)
        det = a * c - b * b
        lam_min = det / lam_max if lam_max > 0.0 else 0.0
        lam_floor = min(lam_floor, lam_min)
        if lam_min > 0.0:
            res_pitch[i] = sigma_v * math.sqrt(c / det)
            res_roll[i] = sigma_v * math.sqrt(a / det)
            cond[i] = math.sqrt(lam_max / lam_min)
        else:
            res_pitch[i] = res_roll[i] = cond[i] = np.inf
        if outputs == 2:
            d = jac[i, 0, 0] * jac[i, 1, 1] - jac[i, 0, 1] * jac[i, 1, 0]
            if d > 0.0:
                n_pos += 1
            elif d < 0.0:
                n_neg += 1
    if outputs == 2:
        if n_pos == 0 and n_neg == 0:
            sign, folded = 0, 1.0
        else:
            sign = 1 if n_pos >= n_neg else -1
            folded = 1.0 - max(n_pos, n_neg) / n
    else:
        sign, unresolved = 0, 0
        for i in range(n):
            if not math.isfinite(res_pitch[i] + res_roll[i]):
                unresolved += 1
        folded = unresolved / n
    return sign, folded, separation_deg * math.sqrt(max(lam_floor, 0.0)) / sigma_v


class _Reflector(NamedTuple):
    inner_radius_mm: float


class _Placement(NamedTuple):
    """What the constraints read of a design: sensors, axes, parts and the shell's inner radius."""

    positions_mm: np.ndarray
    axes: np.ndarray
    models: tuple
    reflector: _Reflector


class FusedObjective(PenalisedObjective):
    """``x -> penalised objective`` of the search, computed by the fused path; picklable.

    The same number as :class:`~reflector_opt.optimiser._evaluation.PenalisedObjective` (the
    worst case over the problem's specular fractions of the objective, or ``PENALTY`` plus
    the scaled violations), and :meth:`evaluate_values` the same constraints and metrics;
    the free-variable vector is read as there (:meth:`values`, :meth:`evaluate`).

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
        Its sensor must have no measured curve (:meth:`applies`).
    step_deg : float
        Search grid step, degrees (at least the 1° of the uniqueness check).
    """

    def __init__(self, problem, step_deg):
        super().__init__(problem, step_deg)
        workspace = problem.workspace
        self.pitch, self.roll = workspace.axes(self.step_deg)
        # the box of the straightforward path: the workspace widened by the stencil's step
        h = JACOBIAN_STEP_DEG
        self.box = PoseBox(
            *((lo - h, hi + h) for lo, hi in (workspace.pitch_deg, workspace.roll_deg))
        )
        node_pitch, node_roll = self.box.points()
        self.node_trig = _grid_trig(node_pitch[:, 0], node_roll[0])
        self.grid_trig = _grid_trig(self.pitch, self.roll)
        self.vander = _vander_and_slope(self.box, self.pitch, self.roll)
        self.flat_pitch, self.flat_roll = (
            a.ravel() for a in np.meshgrid(self.pitch, self.roll, indexing="ij")
        )
        self.fractions = problem.specular_fractions
        self.sigma_v = problem.noise.total_sigma_v
        self.models = (problem.sensor, problem.sensor)
        # roll is symmetric about 0: the mirrored sensor's interpolant negates odd roll terms
        lo, hi = workspace.roll_deg
        self.roll_parity = (-1.0) ** np.arange(self.box.nodes) if lo == -hi else None

    @staticmethod
    def applies(problem, step_deg):
        """Whether the fused path computes this problem's objective on this grid.

        It does for a part without a measured curve (whose correction would depend on the
        axial distance at every stencil pose) on a grid no finer than the uniqueness check's
        1° (its all-pairs comparison grows with the square of the poses), conditions or not.
        """
        return problem.sensor.measured_curve is None and step_deg >= UNIQUENESS_POSE_SEPARATION_DEG

    def evaluate_values(self, values, tightening=None):
        """The candidate at ``values`` (every design variable), judged on the search grid.

        Parameters
        ----------
        values : mapping of str to float
        tightening : mapping of str to float, optional
            Extra margin demanded of named constraints.

        Returns
        -------
        reflector_opt.optimiser._evaluation.Evaluation
            Its ``design`` is the candidate's placement (positions, axes, parts, inner
            radius: what the constraints read), not a full design; for the worst of the
            problem's specular fractions.
        """
        centre, positions, axes, radius = placement(values)
        if not radius > 0.0:
            return Evaluation(values, None, None, (), math.inf, error="no sphere (r_s ≤ 0)")
        frames = sensor_frames(axes, [_DETECTOR, _DETECTOR])
        grid = _geometry(self.grid_trig, centre, positions, frames, radius)
        distance, axial = grid[0], grid[1]
        if not np.all(distance > 0.0):
            return Evaluation(
                values, None, None, (), math.inf, error="a sensor lies on or inside the sphere"
            )
        parts = self._coupling_coefficients(values, centre, positions, frames, radius)
        geometry = _geometry_metrics(self, centre, positions, axes, radius, distance, axial)
        design = _Placement(positions, axes, self.models, _Reflector(self.problem.inner_radius_mm))
        worst = None
        for f in self.fractions:
            metrics = _surface_metrics(
                self, parts.total(self.problem.surface.reflectance, f), *geometry
            )
            constraints = worst_case_constraints(self.problem, design, metrics, tightening or {})
            objective = objective_value(metrics, self.problem.isotropy_weight)
            result = Evaluation(values, design, metrics, constraints, objective)
            if worst is None or result.penalised > worst.penalised:
                worst = result
        return in_conditions(
            self.problem, worst, self.step_deg, tightening=tightening, always=False
        )

    def _coupling_coefficients(self, values, centre, positions, frames, radius):
        """Chebyshev coefficients of the mirror and Lambertian couplings, (n, n, 2) each."""
        nodes = np.moveaxis(_geometry(self.node_trig, centre, positions, frames, radius)[2:], 0, -1)
        symmetric = (
            self.roll_parity is not None
            and values["sensor_azimuth_deg"] == 0.0
            and values["centre_across_mm"] == 0.0
        )
        sensors = 1 if symmetric else 2
        fractions = self.fractions
        share = 1.0 if min(fractions) == 1.0 else 0.0 if max(fractions) == 0.0 else 0.5
        parts = surface_couplings(nodes[:, :, :sensors], radius, share, self.models[:sensors])
        out = []
        for part in (parts.mirror, parts.lambertian):
            c = fit_coefficients(self.box, part)
            if symmetric:
                c = np.concatenate([c, c * self.roll_parity[None, :, None]], axis=-1)
            out.append(c)
        return SurfaceCoupling(mirror=out[0], lambertian=out[1])


def _grid_trig(pitch_deg, roll_deg):
    """cos and sin of pitch (column) and roll (row) spread over the grid as zero-stride views."""
    cp, sp, cr, sr = pose_trig(pitch_deg[:, None], roll_deg[None, :])
    shape = (len(pitch_deg), len(roll_deg))
    return tuple(np.broadcast_to(a, shape) for a in (cp, sp, cr, sr))


def _geometry(trig, centre, positions, frames, radius):
    """:func:`reflector_opt.model._kernel.pose_geometry` on a grid: shape (5, M, N, S)."""
    out = np.empty((5, *trig[0].shape, len(positions)))
    kernel.pose_geometry(*trig, centre, positions, frames, float(radius), out)
    return out


def _vander_and_slope(box, pitch_deg, roll_deg):
    """Chebyshev polynomials at the grid's pitches and rolls and their derivatives per degree."""
    vp, vr = box.vander(pitch_deg, roll_deg)
    n = box.nodes
    slopes = []
    for values, (lo, hi) in ((pitch_deg, box.pitch_deg), (roll_deg, box.roll_deg)):
        x = (2.0 * np.asarray(values) - (lo + hi)) / (hi - lo)
        columns = [
            chebyshev.chebval(x, chebyshev.chebder(np.eye(n)[k])) if k else np.zeros_like(x)
            for k in range(n)
        ]
        slopes.append(np.stack(columns, axis=-1) * (2.0 / (hi - lo)))
    return vp, slopes[0], vr, slopes[1]


def search_objective(problem, step_deg):
    """The penalised objective on a search grid: the fused path where it applies.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
    step_deg : float
        Grid step, degrees.

    Returns
    -------
    FusedObjective or reflector_opt.optimiser._evaluation.PenalisedObjective
        Either has ``evaluate_values(values, tightening=None)``; both are picklable.
    """
    if FusedObjective.applies(problem, step_deg):
        return FusedObjective(problem, step_deg)
    return PenalisedObjective(problem, step_deg)


def _geometry_metrics(fused, centre, positions, axes, radius, distance, axial):
    """Distance window, shell wall, reach and axis misses on ``fused``'s grid."""
    ranges = [m.range_mm for m in fused.models]
    window = distance_window(distance, ranges)
    hits = positions + axial[..., None] * axes
    footprint = np.hypot(
        [m.source_radius_mm for m in fused.models],
        axial * np.tan(np.deg2rad([m.divergence_deg for m in fused.models])),
    )
    wall = shell_wall_mm(
        hits,
        rotate_centre(centre, fused.pitch[:, None], fused.roll[None, :])[..., None, :],
        radius,
        fused.problem.inner_radius_mm,
        footprint,
    )
    reach = reflector_reach_mm(centre, radius, fused.pitch[:, None], fused.roll[None, :])
    return distance, window, wall, reach, float(np.mean(~np.isfinite(axial)))


def _surface_metrics(fused, coefficients, distance, window, wall, reach, missed):
    """:class:`~reflector_opt.analysis._metrics.DesignMetrics` of one surface on ``fused``'s
    grid."""
    vp, dvp, vr, dvr = fused.vander
    flat = np.ascontiguousarray(coefficients)
    eta, d_pitch, d_roll = np.empty((3, len(vp), len(vr), flat.shape[2]))
    for out, left, right in ((eta, vp, vr), (d_pitch, dvp, vr), (d_roll, vp, dvr)):
        kernel.tensor_series_grid(left, flat, right, out)
    h = JACOBIAN_STEP_DEG
    stencil = np.maximum(
        np.stack([eta, eta + h * d_pitch, eta - h * d_pitch, eta + h * d_roll, eta - h * d_roll]),
        0.0,
    )
    v, jac = jacobian_from_stencil(readings(stencil, fused.models), h)
    n = v.shape[0] * v.shape[1]
    res_pitch, res_roll, cond = np.empty(n), np.empty(n), np.empty(n)
    sign, folded, local = judge_poses(
        np.ascontiguousarray(jac.reshape(n, -1, 2)),
        fused.sigma_v,
        UNIQUENESS_POSE_SEPARATION_DEG,
        res_pitch,
        res_roll,
        cond,
    )
    separation = min_separation_sigma(
        v.reshape(n, -1), fused.flat_pitch, fused.flat_roll, fused.sigma_v
    )
    shape = v.shape[:2]
    return DesignMetrics(
        step_deg=fused.step_deg,
        n_poses=n,
        distance_mm=distance,
        distance_min_mm=window[0],
        distance_max_mm=window[1],
        distance_margin_mm=window[2],
        volts_min=v.reshape(n, -1).min(axis=0),
        volts_max=v.reshape(n, -1).max(axis=0),
        axis_miss_fraction=missed,
        resolution_pitch_deg=res_pitch.reshape(shape),
        resolution_roll_deg=res_roll.reshape(shape),
        condition=cond.reshape(shape),
        det_sign=sign,
        fold_fraction=folded,
        min_separation_sigma=separation
        if fused.step_deg <= UNIQUENESS_POSE_SEPARATION_DEG
        else min(separation, local),
        uniqueness_step_deg=fused.step_deg,
        wall_mm=wall,
        reach_mm=reach,
        sigma_v=fused.sigma_v,
    )
