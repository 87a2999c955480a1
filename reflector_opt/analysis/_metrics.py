"""How well a design senses its workspace: every metric of a design on a grid of poses.

:func:`evaluate_metrics` runs the forward model once on the central-difference stencil of
the workspace grid (:mod:`reflector_opt.analysis._jacobian`), judges the Jacobian's
resolution, conditioning, folds and uniqueness (:mod:`reflector_opt.analysis._resolution`)
and adds the design-level margins computed here:

* distance window: the sensor-to-reflector distance d (paper Eq 3) over the workspace and its
  margin to each sensor's usable range;
* mechanics: the thinnest wall of the reflector shell over the band the sensors see, and how
  far the reflector reaches from the unit's axis.

The result, a :class:`DesignMetrics`, is what the optimiser, the tolerance study and the
report read. A design with no sensitivity (a sphere centred at the rotation centre, or an
output clamped at a supply rail) is reported with infinite resolution and condition number,
never an error.
"""

import math
from dataclasses import dataclass, field

import numpy as np

from reflector_opt.analysis._jacobian import (
    JACOBIAN_STEP_DEG,
    jacobian_from_stencil,
    stencil_poses,
)
from reflector_opt.analysis._resolution import (
    UNIQUENESS_POSE_SEPARATION_DEG,
    condition_number,
    crlb_deg,
    fold_fraction,
    jacobian_determinant,
    local_separation_sigma,
    min_separation_sigma,
)
from reflector_opt.model._forward import respond
from reflector_opt.model._geometry import rotate_centre
from reflector_opt.util._display import Summarised, fmt, span
from reflector_opt.util._fileio import json_number

# --- distances and mechanics ------------------------------------------------------------------


def distance_window(distance_mm, range_mm):
    """Distance window of every sensor and its margin to the usable range.

    Parameters
    ----------
    distance_mm : array_like, shape P + (n,)
        Sensor-to-reflector distance d (paper Eq 3) at every pose, mm.
    range_mm : array_like, shape (n, 2)
        Usable (min, max) distance of each sensor, mm.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, numpy.ndarray)
        Per sensor: min d, max d and the margin ``min(d_min − lo, hi − d_max)``, all mm;
        a negative margin means the sensor leaves its range.
    """
    d = np.asarray(distance_mm, dtype=float)
    d = d.reshape(-1, d.shape[-1])
    lo, hi = np.asarray(range_mm, dtype=float).T
    d_min, d_max = d.min(axis=0), d.max(axis=0)
    return d_min, d_max, np.minimum(d_min - lo, hi - d_max)


def shell_wall_mm(hit_point_mm, centre_mm, radius_mm, inner_radius_mm, footprint_mm):
    """Thinnest reflector wall under each sensor's light spot, mm.

    The shell lies between the outer (reflecting) sphere, radius R about the rotated centre
    s1, and the inner sphere of radius r_i about the rotation centre O; both move rigidly
    with the unit, and the inner one is invariant under the rotation. A point s1 + R·u of the
    outer sphere is ``|s1 + R·u| − r_i`` from the inner sphere, and
    ``|s1 + R·u|² = |s1|² + R² + 2R|s1| cos ψ`` with ψ the angle between u and s1. Over the
    spot, a cap of angular radius β = w/R around the normal n = (q − s1)/R at the axis hit q,
    ψ is at most ``angle(n, s1) + β``, so the thinnest wall under the spot is, exactly,
    ``sqrt(|s1|² + R² + 2R|s1| cos(min(π, angle(n, s1) + β))) − r_i``.

    Parameters
    ----------
    hit_point_mm : array_like, shape P + S + (3,)
        Where each sensor's optical axis meets the outer sphere, mm (NaN: a miss).
    centre_mm : array_like, shape P + (1,)*len(S) + (3,)
        Rotated outer-sphere centre s1 at each pose, mm.
    radius_mm : float
        Outer sphere radius R, mm.
    inner_radius_mm : float
        Inner sphere radius r_i (about O), mm.
    footprint_mm : array_like, shape P + S
        Radius w of the light spot on the reflector, mm.

    Returns
    -------
    numpy.ndarray
        Shape P + S, wall thickness in mm (negative: the inner sphere breaks through); NaN
        where the axis misses the sphere.
    """
    s1 = np.asarray(centre_mm, dtype=float)
    r = float(radius_mm)
    offset = np.linalg.norm(s1, axis=-1)
    dot = np.einsum("...i,...i->...", np.asarray(hit_point_mm, dtype=float) - s1, s1) / r
    cos_psi = np.divide(dot, offset, out=np.ones_like(dot), where=offset > 0.0)
    psi = np.arccos(np.clip(cos_psi, -1.0, 1.0))
    worst = np.minimum(np.pi, psi + np.asarray(footprint_mm, dtype=float) / r)
    reach_sq = offset**2 + r * r + 2.0 * r * offset * np.cos(worst)
    return np.sqrt(np.maximum(reach_sq, 0.0)) - float(inner_radius_mm)


def reflector_reach_mm(centre_mm, radius_mm, pitch_deg, roll_deg):
    """How far the reflector sphere reaches from the unit's axis (z) at each pose, mm.

    ``|s1_xy| + R``: the sphere's widest circle about its rotated centre s1.

    Parameters
    ----------
    centre_mm : array_like, shape (3,)
        Sphere centre s0 at zero pose, mm.
    radius_mm : float
        Sphere radius R, mm.
    pitch_deg, roll_deg : array_like
        Poses, degrees.

    Returns
    -------
    numpy.ndarray
        Shape P, mm; it must stay inside the unit's radius.
    """
    s1 = rotate_centre(centre_mm, pitch_deg, roll_deg)
    return np.hypot(s1[..., 0], s1[..., 1]) + float(radius_mm)


# --- all metrics of a design ------------------------------------------------------------------


@dataclass(frozen=True, repr=False)
class DesignMetrics(Summarised):
    """Every metric of one design on one pose grid.

    Attributes
    ----------
    step_deg : float
        Pose grid step, degrees.
    n_poses : int
        Poses on the grid.
    distance_mm : numpy.ndarray, shape P + (n,)
        Sensor-to-reflector distance d (Eq 3) at every pose, mm.
    distance_min_mm, distance_max_mm, distance_margin_mm : numpy.ndarray, shape (n,)
        Distance window per sensor and its margin to the usable range, mm.
    volts_min, volts_max : numpy.ndarray, shape (n,)
        Output voltage window per sensor, V.
    axis_miss_fraction : float
        Fraction of (pose, sensor) pairs where a sensor's axis misses the reflector.
    resolution_pitch_deg, resolution_roll_deg : numpy.ndarray, shape P
        Cramér–Rao 1σ resolution at every pose, degrees (``inf``: no sensitivity).
    condition : numpy.ndarray, shape P
        Condition number of J at every pose.
    det_sign : int
        Prevailing sign of det J (0: J singular everywhere).
    fold_fraction : float
        Fraction of poses where det J is zero or has the other sign (0: no fold).
    min_separation_sigma : float
        Smallest voltage separation of poses ≥ 1° apart, in σ_V (on ``uniqueness_step_deg``;
        on a grid coarser than 1° also its first-order estimate from J, see
        :func:`~reflector_opt.analysis._resolution.local_separation_sigma`).
    uniqueness_step_deg : float
        Grid step of the uniqueness check, degrees.
    wall_mm : numpy.ndarray, shape P + (n,)
        Thinnest reflector wall under each sensor's light spot, mm (NaN: axis misses).
    reach_mm : numpy.ndarray, shape P
        How far the reflector sphere reaches from the unit axis, mm.
    sigma_v : float
        RMS voltage noise used for the resolution, V.
    """

    step_deg: float
    n_poses: int
    distance_mm: np.ndarray = field(repr=False)
    distance_min_mm: np.ndarray
    distance_max_mm: np.ndarray
    distance_margin_mm: np.ndarray
    volts_min: np.ndarray
    volts_max: np.ndarray
    axis_miss_fraction: float
    resolution_pitch_deg: np.ndarray = field(repr=False)
    resolution_roll_deg: np.ndarray = field(repr=False)
    condition: np.ndarray = field(repr=False)
    det_sign: int
    fold_fraction: float
    min_separation_sigma: float
    uniqueness_step_deg: float
    wall_mm: np.ndarray = field(repr=False)
    reach_mm: np.ndarray = field(repr=False)
    sigma_v: float

    def _summary(self):
        """Title and (label, value) rows of :class:`DesignMetrics`."""
        rows = [
            (
                "worst 1σ resolution",
                f"pitch {fmt(self.worst_pitch_deg, unit='°')}, "
                f"roll {fmt(self.worst_roll_deg, unit='°')}",
            ),
            ("worst condition of J", fmt(self.worst_condition)),
            ("det J sign, fold fraction", f"{self.det_sign}, {fmt(self.fold_fraction)}"),
            (
                "min separation",
                f"{fmt(self.min_separation_sigma)} σ_V on a "
                f"{fmt(self.uniqueness_step_deg, unit='°')} grid",
            ),
        ]
        for i in range(len(self.distance_min_mm)):
            distance = span(self.distance_min_mm[i], self.distance_max_mm[i], unit="mm")
            margin = fmt(self.distance_margin_mm[i], unit="mm")
            rows += [
                (f"sensor {i + 1} distance", f"{distance}, margin {margin}"),
                (f"sensor {i + 1} output", span(self.volts_min[i], self.volts_max[i], unit="V")),
            ]
        rows += [
            ("axis miss fraction", fmt(self.axis_miss_fraction)),
            ("thinnest wall under a spot", fmt(self.wall_min_mm, unit="mm")),
            ("largest reach from the axis", fmt(self.reach_max_mm, unit="mm")),
            ("voltage noise σ_V", fmt(self.sigma_v, unit="V")),
        ]
        return f"DesignMetrics: {self.n_poses} poses, {fmt(self.step_deg, unit='°')} grid", rows

    @property
    def wall_min_mm(self):
        """Thinnest wall under the light spots over the grid, mm (``-inf`` if every axis misses)."""
        finite = self.wall_mm[np.isfinite(self.wall_mm)]
        return float(finite.min()) if finite.size else -math.inf

    @property
    def reach_max_mm(self):
        """Largest reach of the reflector sphere from the unit axis over the grid, mm."""
        return float(np.max(self.reach_mm))

    @property
    def worst_pitch_deg(self):
        """Worst-case 1σ pitch resolution over the grid, degrees."""
        return float(np.max(self.resolution_pitch_deg))

    @property
    def worst_roll_deg(self):
        """Worst-case 1σ roll resolution over the grid, degrees."""
        return float(np.max(self.resolution_roll_deg))

    @property
    def worst_resolution_deg(self):
        """The larger of the worst-case pitch and roll resolutions, degrees."""
        return max(self.worst_pitch_deg, self.worst_roll_deg)

    @property
    def worst_condition(self):
        """Largest condition number of J over the grid."""
        return float(np.max(self.condition))

    @property
    def sensitive(self):
        """True when J has full rank at every pose (finite resolution everywhere)."""
        return math.isfinite(self.worst_resolution_deg)

    def to_dict(self):
        """JSON-ready summary; infinite values are ``null`` (with ``sensitive`` false)."""
        return {
            "grid_step_deg": self.step_deg,
            "poses": self.n_poses,
            "sigma_v": self.sigma_v,
            "sensitive": self.sensitive,
            "resolution_deg": {
                "pitch_worst": json_number(self.worst_pitch_deg),
                "roll_worst": json_number(self.worst_roll_deg),
                "pitch_median": json_number(np.median(self.resolution_pitch_deg)),
                "roll_median": json_number(np.median(self.resolution_roll_deg)),
            },
            "condition_worst": json_number(self.worst_condition),
            "det_sign": self.det_sign,
            "fold_fraction": self.fold_fraction,
            "min_separation_sigma": json_number(self.min_separation_sigma),
            "uniqueness_grid_step_deg": self.uniqueness_step_deg,
            "distance_mm": {
                "min": self.distance_min_mm.tolist(),
                "max": self.distance_max_mm.tolist(),
                "margin": self.distance_margin_mm.tolist(),
            },
            "volts": {"min": self.volts_min.tolist(), "max": self.volts_max.tolist()},
            "axis_miss_fraction": self.axis_miss_fraction,
            "wall_min_mm": json_number(self.wall_min_mm),
            "reach_mm": self.reach_max_mm,
        }


def evaluate_metrics(design, step_deg=None, *, uniqueness_step_deg=None, jacobian_step_deg=None):
    """All metrics of a design over its workspace grid.

    One forward-model call on the central-difference stencil of the grid gives the voltages,
    their Jacobian and the distances.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    step_deg : float, optional
        Pose grid step, degrees; defaults to the workspace's own (0.1° in the default).
    uniqueness_step_deg : float, optional
        Grid step of the global uniqueness check, degrees; defaults to ``step_deg`` when that
        is at least 0.25°, else 0.25° (the check compares each pose with its neighbours within
        1°, so its cost grows with (1°/step)²).
    jacobian_step_deg : float, optional
        Central-difference step, degrees (default
        :data:`~reflector_opt.analysis._jacobian.JACOBIAN_STEP_DEG`).

    Returns
    -------
    DesignMetrics
        Raises :class:`~reflector_opt.util._errors.CollisionError` if a sensor touches the sphere.
    """
    step = design.workspace.step_deg if step_deg is None else float(step_deg)
    h = JACOBIAN_STEP_DEG if jacobian_step_deg is None else float(jacobian_step_deg)
    u_step = max(step, 0.25) if uniqueness_step_deg is None else float(uniqueness_step_deg)
    pitch, roll = design.workspace.grid(step)
    response = respond(design, *stencil_poses(pitch, roll, h))
    volts, jac = jacobian_from_stencil(response.volts, h)
    distance = response.distance_mm[0]
    axial = response.axial_distance_mm[0]
    d_min, d_max, margin = distance_window(distance, [m.range_mm for m in design.models])
    sigma_v = design.noise.total_sigma_v
    res_pitch, res_roll = crlb_deg(jac, sigma_v)
    det_sign, folded = _folds(jac, res_pitch, res_roll)
    separation = _separation_sigma(design, (volts, pitch, roll, step), jac, sigma_v, u_step)
    reflector = design.reflector
    flat_volts = volts.reshape(-1, volts.shape[-1])
    return DesignMetrics(
        step_deg=step,
        n_poses=int(distance.size // distance.shape[-1]),
        distance_mm=distance,
        distance_min_mm=d_min,
        distance_max_mm=d_max,
        distance_margin_mm=margin,
        volts_min=flat_volts.min(axis=0),
        volts_max=flat_volts.max(axis=0),
        axis_miss_fraction=float(np.mean(~np.isfinite(axial))),
        resolution_pitch_deg=res_pitch,
        resolution_roll_deg=res_roll,
        condition=condition_number(jac),
        det_sign=det_sign,
        fold_fraction=folded,
        min_separation_sigma=separation,
        uniqueness_step_deg=u_step,
        wall_mm=_shell_wall(design, axial, pitch, roll),
        reach_mm=reflector_reach_mm(reflector.centre_mm, reflector.radius_mm, pitch, roll),
        sigma_v=sigma_v,
    )


def _folds(jac, res_pitch, res_roll):
    """Prevailing sign of det J and the fraction of poses folded against it."""
    if jac.shape[-2] == 2:
        return fold_fraction(jacobian_determinant(jac))
    # more outputs than angles: a fold needs J to lose rank, which the CRLB reports
    return 0, float(np.mean(~np.isfinite(res_pitch + res_roll)))


def _separation_sigma(design, grid, jac, sigma_v, uniqueness_step_deg):
    """Smallest voltage separation of poses ≥ 1° apart, in σ_V (see :class:`DesignMetrics`).

    ``grid`` is ``(volts, pitch, roll, step_deg)`` of the metrics grid, reused when the
    uniqueness grid is the same.
    """
    volts, pitch, roll, step = grid
    if math.isclose(uniqueness_step_deg, step):
        u_volts, u_pitch, u_roll = volts, pitch, roll
    else:
        u_pitch, u_roll = design.workspace.grid(uniqueness_step_deg)
        u_volts = respond(design, u_pitch, u_roll).volts
    separation = min_separation_sigma(u_volts, u_pitch, u_roll, sigma_v)
    if uniqueness_step_deg > UNIQUENESS_POSE_SEPARATION_DEG:
        separation = min(separation, local_separation_sigma(jac, sigma_v))
    return separation


def _shell_wall(design, axial, pitch, roll):
    """Thinnest reflector wall under each sensor's light spot at every pose, mm.

    The spot is centred on the axis hit q = f + t·a (t the axial distance), its radius the
    emitted beam's 1/e radius there, sqrt(ω0² + (t tan θ)²)."""
    reflector, models = design.reflector, design.models
    w0 = np.array([m.source_radius_mm for m in models])
    tan_theta = np.tan(np.deg2rad([m.divergence_deg for m in models]))
    return shell_wall_mm(
        design.positions_mm + axial[..., None] * design.axes,
        rotate_centre(reflector.centre_mm, pitch, roll)[..., None, :],
        reflector.radius_mm,
        reflector.inner_radius_mm,
        np.hypot(w0, axial * tan_theta),
    )
