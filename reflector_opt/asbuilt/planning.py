"""Plans for identification: calibration poses chosen for what they say about the print.

A calibration plan for a polynomial must cover the workspace evenly; a plan for the
as-built identification (:func:`reflector_opt.asbuilt.identification.identify`) need only hold the
poses whose voltages tell the most about a unit's as-built parameters. For one unit of a
design, the p parameters of :class:`~reflector_opt.asbuilt.parameters.Layout` (the shared
surface ρ, f and the unit's own block) each have a prior std σ_p (the tolerance model's),
and each pose i gives the S × p sensitivity block (S sensors)

    A_i = diag(1/σ_eff) · ∂V(pose_i)/∂x · diag(σ_p),

the Jacobian of the weighted voltage residuals of
:class:`~reflector_opt.asbuilt.problem.IdentificationProblem` at the nominal design (the same
residuals, weights σ_eff and central differences the identification uses), in prior-std
units. A plan S has the Bayesian information matrix M(S) = I + Σ_{i∈S} A_iᵀA_i: the
posterior precision in prior-std units, whose inverse's diagonal is each parameter's
(posterior / prior) variance and whose log-determinant is the information the plan gains
over the prior, in nats (2 Σ log(prior/posterior std) along the principal axes).

* :func:`pose_information` — the blocks A_i of a set of poses;
* :func:`greedy_selection` — Bayesian D-optimal forward selection over candidate poses, each
  step the pose of largest det(I_S + A_i M⁻¹ A_iᵀ) (the matrix determinant lemma: a rank-S
  update, S the number of sensors), M⁻¹ kept by the Woodbury identity;
* :func:`exchange` — Fedorov's exchange (the modified form of Cook & Nachtsheim 1980: each
  plan pose in turn swapped for the candidate that raises det M most) until no swap helps;
* :func:`poses_needed` — how many D-optimal poses bring every *determinable* parameter's
  posterior std below a target fraction of its prior std (determinable: it gets there with
  every candidate pose);
* :func:`compare_patterns` — D-optimal against the Sobol and grid patterns
  (:mod:`reflector_opt.calibration.plans`) of the same sizes;
* :func:`check_plans` — the prediction checked by identifying simulated built units
  (:func:`reflector_opt.tolerance.builtunit.build_unit`, exact optics the fast model lacks) on
  each plan: the achieved parameter errors and the angle errors of the identified model;
* :func:`plan_identification` — all of it for ``reflector-opt plan-calibration --for
  identification``, the module's :class:`IdentificationStudy`.

Candidates are a grid over the workspace (:data:`CANDIDATE_STEP_DEG`); a pose is used at
most once. Reference: Atkinson, Donev & Tobias, *Optimum Experimental Designs, with SAS*
(2007), ch. 11–12 (D-optimality, exchange algorithms) and ch. 18 (Bayesian designs).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from reflector_opt.asbuilt.estimator import AsBuiltModel
from reflector_opt.asbuilt.identification import identify
from reflector_opt.asbuilt.parameters import Layout, true_deviations
from reflector_opt.asbuilt.problem import CHECK_STEP_DEG, IdentificationProblem, UnitData
from reflector_opt.asbuilt.uncertainty import DETERMINED_RATIO
from reflector_opt.calibration.plans import make_plan, path_length_deg
from reflector_opt.calibration.simulation import Samples, measure_with_design_noise
from reflector_opt.model.forward import voltages
from reflector_opt.tolerance.builtunit import (
    REFERENCE_SIGMA_DEG,
    build_unit,
    built_unit_protocol,
    crlb_floor_deg,
)
from reflector_opt.tolerance.planning import N_VALIDATION, predict_plans
from reflector_opt.util.display import fmt, html_summary, text_summary
from reflector_opt.util.errors import InputError

__all__ = [
    "CANDIDATE_STEP_DEG",
    "MAX_CANDIDATES",
    "PATTERNS",
    "SIZES",
    "CheckRow",
    "IdentificationStudy",
    "PatternRow",
    "PoseCount",
    "PoseInformation",
    "candidate_poses",
    "check_plans",
    "compare_patterns",
    "d_optimal",
    "exchange",
    "greedy_selection",
    "minimum_poses",
    "plan_identification",
    "pose_information",
    "poses_needed",
    "visiting_order",
]

#: Step of the candidate grid over the workspace, degrees (±15° gives 31 × 31 = 961 poses).
CANDIDATE_STEP_DEG = 1.0

#: Plan patterns compared for identification, in report order.
PATTERNS = ("d-optimal", "sobol", "grid")

#: Plan sizes compared (poses).
SIZES = (25, 50, 100, 200)

#: Most candidate poses (the greedy path over all of them costs N² S p² operations).
MAX_CANDIDATES = 4000

#: Largest number of exchange passes over the plan.
MAX_PASSES = 20

#: A swap is taken when it raises log det M by more than this (nats).
_SWAP_GAIN = 1e-9


@dataclass(frozen=True)
class PoseInformation:
    """Each pose's sensitivity block for one unit's as-built parameters, in prior-std units.

    Attributes
    ----------
    poses_deg : numpy.ndarray
        Shape (n, 2): pitch, roll, degrees.
    rows : numpy.ndarray
        Shape (n, S, p): A_i = ∂(V/σ_eff)/∂(x/σ_p) at each pose, dimensionless.
    names : tuple of str
        The p free parameters (shared surface first, then the unit's block).
    prior_std : numpy.ndarray
        Shape (p,): prior std of each, in its own unit (mm, degrees, V, fraction).
    settings : dict
        The keyword arguments of :func:`pose_information` it was computed with (design,
        prior, reference noise), so that :meth:`at` computes other poses alike.
    """

    poses_deg: np.ndarray
    rows: np.ndarray
    names: tuple
    prior_std: np.ndarray
    settings: dict = field(default_factory=dict, repr=False, compare=False)

    def __len__(self):
        return len(self.poses_deg)

    def information(self, indices=None):
        """M = I + Σ A_iᵀA_i over ``indices`` (default every pose), shape (p, p)."""
        rows = self.rows if indices is None else self.rows[np.asarray(indices, dtype=int)]
        flat = rows.reshape(-1, rows.shape[-1])
        return np.eye(rows.shape[-1]) + flat.T @ flat

    def log_det(self, indices=None):
        """log det M: the information gained over the prior, nats."""
        return float(np.linalg.slogdet(self.information(indices))[1])

    def ratio(self, indices=None):
        """Posterior over prior std of every parameter, shape (p,)."""
        return np.sqrt(np.diag(np.linalg.inv(self.information(indices))))

    def at(self, poses_deg):
        """The same information at other poses (same design, prior and noise)."""
        return pose_information(poses_deg=poses_deg, **self.settings)


def pose_information(
    design,
    poses_deg,
    *,
    tolerances=None,
    surface_std=None,
    reference_sigma_deg=REFERENCE_SIGMA_DEG,
):
    """The sensitivity blocks of one unit's as-built parameters at the given poses.

    The Jacobian is :meth:`reflector_opt.asbuilt.problem.IdentificationProblem.data_jacobian` at the
    nominal design (the design's own voltages as the data), so the weights σ_eff (voltage
    noise with quantisation and the angle reference's noise through the slope) are the
    identification's.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    poses_deg : array_like
        Shape (n, 2): pitch, roll within the workspace, degrees.
    tolerances : reflector_opt.tolerance.model.Tolerances, optional
        The prior (default: the tolerance model's defaults).
    surface_std : dict, optional
        Prior std of ``reflectance`` and ``specular_fraction`` (absolute).
    reference_sigma_deg : float
        RMS noise of the angle reference at each pose, degrees.

    Returns
    -------
    PoseInformation
    """
    poses = np.asarray(poses_deg, dtype=float)
    if poses.ndim != 2 or poses.shape[1] != 2 or len(poses) == 0 or not np.isfinite(poses).all():
        raise InputError(f"poses: expected finite (n, 2) angles, got shape {poses.shape}")
    layout = Layout(design, 1, tolerances, surface_std)
    nominal = voltages(design, poses[:, 0], poses[:, 1])
    problem = IdentificationProblem(
        layout, [UnitData("design", nominal, poses)], reference_sigma_deg
    )
    jacobian = problem.data_jacobian(np.zeros(layout.size))
    free = problem.free
    rows = jacobian[:, free] * problem.prior_std[free]
    names = tuple(
        name.split(": ")[-1] for name, keep in zip(layout.names(), free, strict=True) if keep
    )
    settings = {
        "design": design,
        "tolerances": tolerances,
        "surface_std": surface_std,
        "reference_sigma_deg": reference_sigma_deg,
    }
    rows = rows.reshape(len(poses), layout.n_sensors, -1)
    return PoseInformation(poses, rows, names, problem.prior_std[free], settings)


def candidate_poses(workspace, step_deg=CANDIDATE_STEP_DEG):
    """The candidate grid over the workspace, both ends included: shape (n, 2), degrees.

    Parameters
    ----------
    workspace : reflector_opt.design.components.Workspace
    step_deg : float
        Grid step, degrees.

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    InputError
        More than :data:`MAX_CANDIDATES` poses.
    """
    pitch, roll = workspace.axes(step_deg)
    if len(pitch) * len(roll) > MAX_CANDIDATES:
        raise InputError(
            f"candidate step {step_deg:g}°: {len(pitch) * len(roll):,} candidate poses, more "
            f"than {MAX_CANDIDATES:,}; give a coarser step"
        )
    grid_pitch, grid_roll = np.meshgrid(pitch, roll, indexing="ij")
    return np.column_stack([grid_pitch.ravel(), grid_roll.ravel()])


def greedy_selection(rows, n_poses, stop_variance=None):
    """Bayesian D-optimal forward selection: each step the pose that raises det M most.

    With M⁻¹ known, adding pose i multiplies det M by det(I_S + A_i M⁻¹ A_iᵀ) (the matrix
    determinant lemma), evaluated for every candidate at once; M⁻¹ is then updated by the
    Woodbury identity, M⁻¹ − M⁻¹A_iᵀ (I_S + A_i M⁻¹ A_iᵀ)⁻¹ A_i M⁻¹. No pose is taken twice.

    Parameters
    ----------
    rows : numpy.ndarray
        Shape (N, S, p): the candidates' blocks (:attr:`PoseInformation.rows`).
    n_poses : int
        Poses to select, at most N.
    stop_variance : numpy.ndarray, optional
        Shape (p,): stop early once every diag M⁻¹ is at most this (``inf``: no limit).

    Returns
    -------
    order : numpy.ndarray
        Shape (n,): candidate indices in the order taken (n = n_poses unless stopped).
    gains : numpy.ndarray
        Shape (n,): log det M gained at each step, nats (their sum is log det M).
    variances : numpy.ndarray
        Shape (n, p): diag M⁻¹ after each step (posterior over prior variance).
    """
    n_candidates, n_sensors, p = rows.shape
    if not 1 <= n_poses <= n_candidates:
        raise InputError(f"plan size: expected 1 to {n_candidates} poses, got {n_poses}")
    inverse = np.eye(p)
    taken = np.zeros(n_candidates, dtype=bool)
    order, gains, variances = [], [], []
    transposed = rows.transpose(0, 2, 1)
    for _ in range(int(n_poses)):
        projected = rows @ inverse  # (N, S, p): A_i M⁻¹
        update = np.eye(n_sensors) + projected @ transposed
        gain = np.linalg.slogdet(update)[1]
        gain[taken] = -np.inf
        i = int(np.argmax(gain))
        inverse = inverse - projected[i].T @ np.linalg.solve(update[i], projected[i])
        inverse = 0.5 * (inverse + inverse.T)
        taken[i] = True
        order.append(i)
        gains.append(gain[i])
        variances.append(np.diag(inverse).copy())
        if stop_variance is not None and np.all(variances[-1] <= stop_variance):
            break
    return np.array(order), np.array(gains), np.array(variances)


def exchange(rows, chosen, max_passes=MAX_PASSES):
    """Fedorov exchange: swap plan poses for candidates while det M rises.

    Each pass visits every pose of the plan: with that pose removed (a rank-S downdate,
    det factor det(I_S − A_i M⁻¹ A_iᵀ)) the candidate that restores the most information is
    found as in :func:`greedy_selection`, and swapped in if it beats the pose it replaces.

    Parameters
    ----------
    rows : numpy.ndarray
        Shape (N, S, p): the candidates' blocks.
    chosen : array_like of int
        The starting plan (distinct candidate indices).
    max_passes : int
        Passes over the plan at most.

    Returns
    -------
    numpy.ndarray
        The improved plan's candidate indices (same size; log det M never lower).
    """
    chosen = np.array(chosen, dtype=int)
    n_sensors, p = rows.shape[1:]
    identity = np.eye(n_sensors)
    transposed = rows.transpose(0, 2, 1)
    for _ in range(int(max_passes)):
        flat = rows[chosen].reshape(-1, p)
        inverse = np.linalg.inv(np.eye(p) + flat.T @ flat)  # afresh each pass: no drift
        swaps = 0
        for k in range(len(chosen)):
            i = chosen[k]
            a = rows[i]
            down = identity - a @ inverse @ a.T
            loss = np.linalg.slogdet(down)[1]
            without = inverse + (a @ inverse).T @ np.linalg.solve(down, a @ inverse)
            projected = rows @ without
            update = identity + projected @ transposed
            gain = np.linalg.slogdet(update)[1]
            gain[chosen] = -np.inf
            j = int(np.argmax(gain))
            if gain[j] + loss > _SWAP_GAIN:
                chosen[k] = j
                inverse = without - projected[j].T @ np.linalg.solve(update[j], projected[j])
                swaps += 1
        if swaps == 0:
            break
    return chosen


def d_optimal(info, n_poses):
    """A D-optimal plan of ``n_poses`` candidates: greedy selection, then exchange.

    Parameters
    ----------
    info : PoseInformation
        The candidates.
    n_poses : int

    Returns
    -------
    numpy.ndarray
        Candidate indices of the plan.
    """
    order, _, _ = greedy_selection(info.rows, n_poses)
    return exchange(info.rows, order)


def visiting_order(poses_deg):
    """The order a rig visits a plan in: row by row of pitch, every other row reversed.

    Parameters
    ----------
    poses_deg : array_like
        Shape (n, 2): pitch, roll, degrees.

    Returns
    -------
    numpy.ndarray
        Shape (n,): indices into ``poses_deg`` in visiting order.
    """
    poses = np.asarray(poses_deg, dtype=float)
    order = []
    for k, pitch in enumerate(np.unique(poses[:, 0])):
        row = np.flatnonzero(poses[:, 0] == pitch)
        row = row[np.argsort(poses[row, 1], kind="stable")]
        order.extend(row[::-1] if k % 2 else row)
    return np.array(order, dtype=int)


def minimum_poses(info):
    """The fewest poses an identification accepts: one voltage per parameter, rounded up."""
    n_sensors, p = info.rows.shape[1:]
    return -(-p // n_sensors)


@dataclass(frozen=True)
class PoseCount:
    """Poses a D-optimal plan needs to bring each determinable parameter to the target.

    Attributes
    ----------
    target : float
        Posterior over prior std to reach (0.5: halve the prior's).
    n_poses : int
        The plan size that brings every determinable parameter there (0 if none is).
    needed : dict of str to int or None
        Per parameter, the poses of the D-optimal sequence after which it first meets the
        target; None for a parameter that does not even with every candidate.
    ratio_all : numpy.ndarray
        Posterior over prior std with every candidate pose, shape (p,).
    indices : numpy.ndarray
        Candidate indices of the chosen plan (greedy, then exchange if that keeps the
        target).
    """

    target: float
    n_poses: int
    needed: dict
    ratio_all: np.ndarray
    indices: np.ndarray

    @property
    def determinable(self):
        """Names of the parameters that reach the target."""
        return tuple(name for name, n in self.needed.items() if n is not None)


def poses_needed(info, target=DETERMINED_RATIO):
    """The D-optimal plan size that brings every determinable parameter below the target.

    The greedy sequence is nested, so each parameter's posterior variance falls along it;
    the count is the step at which the last determinable parameter meets the target, and at
    least :func:`minimum_poses` (the identification refuses fewer voltages than
    parameters). The sequence stops there. The plan of that size is then improved by
    :func:`exchange`; if the exchange (which raises det M, not each marginal) loses a
    parameter's target, the greedy plan is kept.

    Parameters
    ----------
    info : PoseInformation
        The candidates.
    target : float
        Posterior over prior std to reach, in (0, 1).

    Returns
    -------
    PoseCount
    """
    if not 0.0 < target < 1.0:
        raise InputError(
            f"target std: expected a fraction of the prior std in (0, 1), got {target}"
        )
    ratio_all = info.ratio()
    determinable = ratio_all <= target
    needed = dict.fromkeys(info.names)
    if not determinable.any():
        return PoseCount(float(target), 0, needed, ratio_all, np.zeros(0, dtype=int))
    stop = np.where(determinable, target**2, np.inf)
    order, _, variances = greedy_selection(info.rows, len(info), stop)
    met = variances <= target**2
    for j in np.flatnonzero(determinable):  # at most every candidate (rounding)
        needed[info.names[j]] = int(np.argmax(met[:, j])) + 1 if met[:, j].any() else len(order)
    # the identification needs a voltage per parameter at least
    n_poses = max(max(n for n in needed.values() if n is not None), minimum_poses(info))
    if n_poses > len(order):
        order, _, _ = greedy_selection(info.rows, n_poses)
    indices = exchange(info.rows, order[:n_poses])
    if np.any(info.ratio(indices)[determinable] > target):
        indices = order[:n_poses]
    return PoseCount(float(target), n_poses, needed, ratio_all, np.asarray(indices))


@dataclass(frozen=True)
class PatternRow:
    """What the Fisher information predicts for one plan.

    Attributes
    ----------
    pattern : str
    n_poses : int
    log_det : float
        log det M, nats.
    ratio : numpy.ndarray
        Shape (p,): posterior over prior std of each parameter.
    poses_deg : numpy.ndarray
        Shape (n, 2): the plan in visiting order, degrees.
    """

    pattern: str
    n_poses: int
    log_det: float
    ratio: np.ndarray
    poses_deg: np.ndarray = field(repr=False)

    def to_dict(self, names, target):
        """JSON-ready, with the parameters whose ratio is at most ``target``."""
        return {
            "pattern": self.pattern,
            "n_poses": self.n_poses,
            "log_det": self.log_det,
            "path_deg": path_length_deg(self.poses_deg),
            "posterior_prior_ratio": dict(zip(names, self.ratio.tolist(), strict=True)),
            "determined": [n for n, r in zip(names, self.ratio, strict=True) if r <= target],
        }


def _row(pattern, poses, rows):
    """The PatternRow of a plan from its poses and their blocks."""
    flat = rows.reshape(-1, rows.shape[-1])
    information = np.eye(flat.shape[1]) + flat.T @ flat
    ordered = poses[visiting_order(poses)] if pattern == "d-optimal" else poses
    return PatternRow(
        pattern,
        len(poses),
        float(np.linalg.slogdet(information)[1]),
        np.sqrt(np.diag(np.linalg.inv(information))),
        ordered,
    )


def compare_patterns(info, sizes=SIZES, patterns=PATTERNS, seed=0):
    """The Fisher prediction of every pattern and size: log det M and each parameter's ratio.

    Parameters
    ----------
    info : PoseInformation
        The candidates (their settings give the design and prior of the other patterns).
    sizes : sequence of int
        Plan sizes (``grid`` takes the nearest square).
    patterns : sequence of str
        Among :data:`PATTERNS`, and ``spiral`` and ``raster``
        (:data:`reflector_opt.calibration.plans.PATTERNS`; the raster ignores the size).
    seed : int
        Scrambling seed of the Sobol points.

    Returns
    -------
    list of PatternRow
        Pattern by pattern, sizes in the order given.
    """
    workspace = info.settings["design"].workspace
    out = []
    for pattern in patterns:
        for n in sizes if pattern != "raster" else (None,):
            if pattern == "d-optimal":
                indices = d_optimal(info, n)
                out.append(_row(pattern, info.poses_deg[indices], info.rows[indices]))
            else:
                poses = make_plan(workspace, pattern, n, seed=seed)
                out.append(_row(pattern, poses, info.at(poses).rows))
    return out


@dataclass(frozen=True)
class CheckRow:
    """One plan checked by identifying simulated built units on it.

    Attributes
    ----------
    pattern : str
    n_poses : int
    achieved : numpy.ndarray
        Shape (p,): RMS over the units of (estimate − truth) / prior std per parameter.
    rms_deg : numpy.ndarray
        Pitch and roll: RMS angle error of the identified model inverted at the validation
        poses, pooled over the units (RMS of the units' RMS), degrees.
    floor_deg : numpy.ndarray
        The units' Cramér–Rao floor at the same poses, pooled alike, degrees.
    inflation : float
        The largest Birge ratio s² of the units' fits.
    seconds : float
        Wall time of the identifications, s.
    """

    pattern: str
    n_poses: int
    achieved: np.ndarray
    rms_deg: np.ndarray
    floor_deg: np.ndarray
    inflation: float
    seconds: float

    def to_dict(self, names):
        """JSON-ready, with the angle errors' ratio to the floor."""
        ratio = self.rms_deg / self.floor_deg
        return {
            "pattern": self.pattern,
            "n_poses": self.n_poses,
            "achieved_error_prior_ratio": dict(zip(names, self.achieved.tolist(), strict=True)),
            "rms_deg": {"pitch": float(self.rms_deg[0]), "roll": float(self.rms_deg[1])},
            "floor_ratio": {"pitch": float(ratio[0]), "roll": float(ratio[1])},
            "inflation": self.inflation,
            "seconds": self.seconds,
        }


@dataclass(frozen=True)
class ModelUnit:
    """A unit made by the identification's own model: its parameters drawn from the prior.

    The Fisher prediction is exact for such units up to the model's nonlinearity, so
    identifying them checks the prediction itself; a built unit
    (:class:`reflector_opt.tolerance.builtunit.BuiltUnit`) adds the model-form error of the
    exact optics. Duck-types a built unit for
    :func:`~reflector_opt.tolerance.builtunit.built_unit_protocol` and
    :func:`~reflector_opt.tolerance.builtunit.crlb_floor_deg`.

    Attributes
    ----------
    design : reflector_opt.design.design.Design
        The unit's geometry and surface (fast model).
    mismatch : reflector_opt.model.noise.Mismatch
    index : int
    x : numpy.ndarray
        Its parameter vector (deviations from the design, :class:`Layout` with one unit).
    """

    design: object
    mismatch: object
    index: int
    x: np.ndarray

    @classmethod
    def draw(cls, layout, index, seed=0):
        """Unit ``index`` of ``seed``: x ~ N(0, prior), clipped to the fit's bounds."""
        rng = np.random.default_rng([int(seed), int(index), 11])
        lower, upper = layout.bounds()
        x = np.clip(layout.prior_std() * rng.standard_normal(layout.size), lower, upper)
        design = layout.design
        working = design.replace(workspace=replace(design.workspace, step_deg=CHECK_STEP_DEG))
        built, mismatch = layout.unit_design(x, 0, working)
        return cls(built, mismatch, int(index), x)

    def volts(self, pitch_deg, roll_deg):
        """Noise-free output voltages (gain and offset applied), V, shape ``P + (S,)``."""
        return self.mismatch.apply(voltages(self.design, pitch_deg, roll_deg))

    def record(self, angles_deg, rng, reference_sigma_deg=REFERENCE_SIGMA_DEG):
        """What a rig logs: the design's noise and ADC, the reference's noise on the angles."""
        angles = np.asarray(angles_deg, dtype=float)
        true = self.volts(angles[:, 0], angles[:, 1])
        volts = measure_with_design_noise(self.design, true, rng)
        read = angles + rng.normal(0.0, reference_sigma_deg, angles.shape)
        return Samples(read, true, volts)


def _truth(design, unit):
    """The parameter vector (deviations: surface, then block) of a built or model unit."""
    if isinstance(unit, ModelUnit):
        return unit.x
    surface = [
        unit.design.reflector.reflectance - design.reflector.reflectance,
        unit.design.reflector.specular_fraction - design.reflector.specular_fraction,
    ]
    return np.r_[surface, true_deviations(design, unit.design, unit.mismatch)]


def _angle_rms_deg(result, validation):
    """RMS pitch and roll error of an identified unit's model inverted at validation data."""
    estimate = AsBuiltModel(*result.as_built(0)).predict(validation.volts)
    return np.sqrt(np.mean((estimate - validation.angles_deg) ** 2, axis=0))


def check_plans(
    design,
    plans,
    *,
    n_units=3,
    seed=0,
    truth="built",
    n_validation=N_VALIDATION,
    progress=None,
    **prior,
):
    """Identify simulated units on each plan and measure what the fit achieves.

    Each unit records the plan with its noise and the angle reference's
    (:func:`~reflector_opt.tolerance.builtunit.built_unit_protocol`: for built units the same
    draws as :func:`reflector_opt.tolerance.planning.predict_plans` for the same plan and
    seed), is identified alone (:func:`~reflector_opt.asbuilt.identification.identify`, no
    profiles), and its identified model is inverted at the validation poses.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
        Two sensors.
    plans : sequence of (str, array_like)
        (pattern name, poses (n, 2) in degrees).
    n_units : int
        Units per plan (the same units for every plan).
    seed : int
        Seed of the units and every noise draw.
    truth : {"built", "model"}
        ``built``: :func:`~reflector_opt.tolerance.builtunit.build_unit` (drawn from the
        tolerance model, exact optics: the model-form error included); ``model``:
        :class:`ModelUnit` (the prediction's own assumptions).
    n_validation : int
        Validation poses per unit.
    progress : callable, optional
        Called with a short text before each plan.
    **prior
        ``tolerances``, ``surface_std``, ``reference_sigma_deg``: as :func:`pose_information`.

    Returns
    -------
    list of CheckRow
    """
    layout = Layout(design, 1, prior.get("tolerances"), prior.get("surface_std"))
    units = _simulated_units(layout, truth, n_units, seed)
    # exact reference and optics, as the plans' information: no reference, spread or terms
    settings = {"design": design, "reference_sigma_deg": REFERENCE_SIGMA_DEG, **prior}
    settings.update(reference_std=None, model_form=None, subsurface_std=None)
    out = []
    for pattern, poses in plans:
        if progress is not None:
            progress(f"identifying {n_units} units on {pattern} {len(poses)} poses")
        started = time.perf_counter()
        found = [_identify_unit(unit, poses, seed, n_validation, settings) for unit in units]
        errors, rms, floors, inflation = zip(*found, strict=True)
        pooled = [np.sqrt(np.mean(np.square(v), axis=0)) for v in (errors, rms, floors)]
        seconds = time.perf_counter() - started
        out.append(CheckRow(pattern, len(poses), *pooled, float(max(inflation)), seconds))
    return out


def _simulated_units(layout, truth, n_units, seed):
    """The units a check identifies: built units or units of the model."""
    if truth == "built":
        design, tolerances = layout.design, layout.tolerances
        return [build_unit(design, i, seed=seed, tolerances=tolerances) for i in range(n_units)]
    if truth == "model":
        return [ModelUnit.draw(layout, i, seed) for i in range(n_units)]
    raise InputError(f"truth: expected 'built' or 'model', got {truth!r}")


def _identify_unit(unit, poses, seed, n_validation, settings):
    """Record a unit on a plan, identify it; its scaled errors, angle RMS, floor, s²."""
    design = settings["design"]
    protocol = built_unit_protocol(
        unit,
        poses,
        n_validation=n_validation,
        seed=seed,
        reference_sigma_deg=settings["reference_sigma_deg"],
    )
    calibration, validation = protocol.calibration, protocol.validation
    result = identify(
        design,
        {"1": (calibration.volts, calibration.angles_deg)},
        profiles=False,
        **{k: v for k, v in settings.items() if k != "design"},
    )
    prior = result.layout.prior_std()
    free = prior > 0
    error = ((result.x - _truth(design, unit)) / np.where(free, prior, 1.0))[free]
    return (
        error,
        _angle_rms_deg(result, validation),
        crlb_floor_deg(unit, validation.angles_deg),
        result.inflation,
    )


@dataclass(frozen=True)
class IdentificationStudy:
    """A plan for identification and what backs it.

    Attributes
    ----------
    info : PoseInformation
        The candidate poses and their sensitivity blocks.
    count : PoseCount
        The poses the D-optimal plan needs to reach the target.
    plan : PatternRow or None
        The chosen D-optimal plan (``count.n_poses`` poses, visiting order); None when no
        parameter reaches the target.
    rows : list of PatternRow
        Every pattern and size compared.
    checks : list of CheckRow
        The identifications of simulated units on each compared plan, then on the chosen
        one (pattern ``chosen``); empty when not checked.
    comparison : reflector_opt.tolerance.planning.PlanStudy or None
        The calibration forms on the same units, plans and noise draws.
    n_units, seed : int
    truth : str
        ``built`` or ``model`` (:func:`check_plans`).
    candidate_step_deg : float
        Step of the candidate grid, degrees.
    """

    info: PoseInformation
    count: PoseCount
    plan: PatternRow
    rows: list
    checks: list
    comparison: object
    n_units: int
    seed: int
    truth: str
    candidate_step_deg: float

    def __repr__(self):
        return text_summary(*_summary(self))

    def _repr_html_(self):
        return html_summary(*_summary(self))

    def check(self, pattern, n_poses):
        """The CheckRow of a plan, or None."""
        return next((c for c in self.checks if (c.pattern, c.n_poses) == (pattern, n_poses)), None)

    def within_floor(self, within=0.10):
        """Smallest plan per method and pattern whose angle RMS is within a fraction of the floor.

        Parameters
        ----------
        within : float
            Allowed excess over the units' Cramér–Rao floor on both angles.

        Returns
        -------
        dict
            ``{"identification": {pattern: n or None}, form: {pattern: n or None}, …}``.
        """
        out = {"identification": {}}
        for row in self.rows:
            found = self.check(row.pattern, row.n_poses)
            if found is None:
                continue
            ok = np.all(found.rms_deg <= (1.0 + within) * found.floor_deg)
            best = out["identification"].get(row.pattern)
            if ok and (best is None or row.n_poses < best):
                best = row.n_poses
            out["identification"][row.pattern] = best
        if self.comparison is not None:
            floor = self.comparison.floor_rms_deg
            for p in self.comparison.predictions:
                table = out.setdefault(p.form, {})
                best = table.get(p.pattern)
                if np.all(p.rms_deg <= (1.0 + within) * floor):
                    best = p.n_poses if best is None else min(best, p.n_poses)
                table[p.pattern] = best
        return out

    def to_dict(self, within=0.10):
        """JSON-ready: settings, per-parameter figures, every plan and its check."""
        names, chosen = self.info.names, self.check("chosen", self.count.n_poses)
        parameters = _parameter_entries(self, chosen)
        patterns = []
        for row in self.rows:
            entry = row.to_dict(names, self.count.target)
            found = self.check(row.pattern, row.n_poses)
            entry["check"] = None if found is None else found.to_dict(names)
            patterns.append(entry)
        return {
            "for": "identification",
            "target_std_ratio": self.count.target,
            "candidates": {
                "step_deg": self.candidate_step_deg,
                "n_poses": len(self.info),
            },
            "reference_sigma_deg": float(self.info.settings["reference_sigma_deg"]),
            "n_units": self.n_units,
            "seed": self.seed,
            "truth": self.truth,
            "parameters": parameters,
            "recommended": None if self.plan is None else self._recommended(chosen),
            "patterns": patterns,
            "within": within,
            "smallest_within_floor": self.within_floor(within),
            "calibration": None if self.comparison is None else self.comparison.to_dict(),
        }

    def _recommended(self, chosen):
        out = self.plan.to_dict(self.info.names, self.count.target)
        out["determinable"] = list(self.count.determinable)
        out["check"] = None if chosen is None else chosen.to_dict(self.info.names)
        return out


def _parameter_entries(study, chosen):
    """Per parameter of an :class:`IdentificationStudy`: its prior, std ratios and the poses
    it needs (JSON-ready); ``chosen`` is the check of the chosen plan, or None."""
    entries = []
    for j, name in enumerate(study.info.names):
        entry = {
            "name": name,
            "prior_std": float(study.info.prior_std[j]),
            "ratio_all_candidates": float(study.count.ratio_all[j]),
            "poses_needed": study.count.needed[name],
        }
        if study.plan is not None:
            entry["plan_ratio"] = float(study.plan.ratio[j])
        if chosen is not None:
            entry["achieved_ratio"] = float(chosen.achieved[j])
        entries.append(entry)
    return entries


def _check_request(design, info, patterns, sizes, compare_forms, truth):
    """Refuse patterns, sizes and comparisons the identification planner cannot make."""
    if len(design.sensors) != 2:
        raise InputError("plan for identification: the design must have exactly two sensors")
    allowed = ("d-optimal", "sobol", "grid", "spiral")
    unknown = [p for p in patterns if p not in allowed]
    if unknown:
        raise InputError(
            f"patterns: {', '.join(unknown)} cannot be planned for identification; "
            f"known: {', '.join(allowed)}"
        )
    least = minimum_poses(info)
    small = [n for n in sizes if n < least]
    if small:
        raise InputError(
            f"sizes: {small[0]} poses are too few to identify {len(info.names)} parameters "
            f"from {len(design.sensors)} sensors; give at least {least}"
        )
    if "d-optimal" in patterns and max(sizes, default=0) > len(info):
        raise InputError(
            f"sizes: {max(sizes)} poses exceed the {len(info)} candidates of the candidate "
            "grid; give a finer candidate step"
        )
    if compare_forms and truth != "built":
        raise InputError("calibration forms are compared on built units only (truth 'built')")


def _comparison(design, forms, patterns, sizes, n_units, seed, progress):
    """The calibration forms' predictions on the same units and plans (or None)."""
    if not forms or not n_units:
        return None
    if progress is not None:
        progress(f"calibration forms {', '.join(forms)} on the same units")
    return predict_plans(
        design,
        forms=tuple(forms),
        patterns=tuple(p for p in patterns if p != "d-optimal"),
        sizes=tuple(sizes),
        n_units=n_units,
        seed=seed,
    )


def plan_identification(
    design,
    *,
    sizes=SIZES,
    patterns=PATTERNS,
    target=DETERMINED_RATIO,
    n_units=3,
    seed=0,
    truth="built",
    compare_forms=(),
    candidate_step_deg=CANDIDATE_STEP_DEG,
    progress=None,
):
    """Plan a calibration for identification: the D-optimal plan, its size, its check.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
        Two sensors.
    sizes : sequence of int
        Plan sizes to compare (poses).
    patterns : sequence of str
        Among ``d-optimal``, ``sobol``, ``grid``, ``spiral``.
    target : float
        Posterior over prior std each determinable parameter must reach, in (0, 1).
    n_units : int
        Simulated units each plan is checked on (0: no check).
    seed : int
        Seed of the units, the Sobol scrambling and every noise draw.
    truth : {"built", "model"}
        The simulated units (:func:`check_plans`).
    compare_forms : sequence of str
        Calibration forms to predict on the same units and plans
        (:func:`reflector_opt.tolerance.planning.predict_plans`; needs built units).
    candidate_step_deg : float
        Step of the candidate grid, degrees.
    progress : callable, optional
        Called with a short text before each long step.

    Returns
    -------
    IdentificationStudy
    """
    info = pose_information(design, candidate_poses(design.workspace, candidate_step_deg))
    _check_request(design, info, patterns, sizes, compare_forms, truth)
    count = poses_needed(info, target)
    plan = None
    if count.n_poses:
        plan = _row("d-optimal", info.poses_deg[count.indices], info.rows[count.indices])
    rows = compare_patterns(info, sizes, patterns, seed)
    plans = [(r.pattern, r.poses_deg) for r in rows]
    plans += [] if plan is None else [("chosen", plan.poses_deg)]
    checks = []
    if n_units:
        checks = check_plans(
            design, plans, n_units=n_units, seed=seed, truth=truth, progress=progress
        )
    comparison = _comparison(design, compare_forms, patterns, sizes, n_units, seed, progress)
    settings = (int(n_units), int(seed), truth, float(candidate_step_deg))
    return IdentificationStudy(info, count, plan, rows, checks, comparison, *settings)


def _summary(study):
    """Title and (label, value) rows of :class:`IdentificationStudy`."""
    plan = study.plan
    rows = [
        ("target std ratio", fmt(study.count.target)),
        ("poses needed", str(study.count.n_poses)),
        (
            "chosen plan",
            "none reaches the target"
            if plan is None
            else f"{plan.pattern}, {plan.n_poses} poses, log det M {fmt(plan.log_det)}",
        ),
        ("plans compared", str(len(study.rows))),
        ("plans checked", str(len(study.checks))),
        (
            "calibration forms compared",
            "no"
            if study.comparison is None
            else f"{len(study.comparison.predictions)} predictions",
        ),
        ("candidate grid step", fmt(study.candidate_step_deg, unit="°")),
    ]
    title = f"IdentificationStudy: {study.n_units} units ({study.truth} truth), seed {study.seed}"
    return title, rows
