"""The optimiser in operating conditions: the error budget as objective, drift as a limit.

With operating conditions (:attr:`Problem.conditions
<reflector_opt.optimiser._problem.Problem.conditions>`, the ``[conditions]`` table of
docs/conditions.md) a candidate is judged by its worst-case total error in them,
:attr:`ErrorBudget.worst_case_deg <reflector_opt.analysis._budget.ErrorBudget.worst_case_deg>`:
at every pose and for each angle the root-sum-square of every source's worst-scenario error
(the noise at 1σ), its largest over the workspace. Per angle,

    T_γ = max over poses sqrt(Σ_sources e_γ²),   T_α likewise,

and the objective is ``max(T_γ, T_α) · (1 + w·|ln(T_γ/T_α)|)`` with the problem's isotropy
weight w, the white-noise objective's form
(:func:`~reflector_opt.optimiser._evaluation.objective_value`): with every condition at zero
the budget holds the noise alone, T is the worst Cramér–Rao 1σ resolution, and the two
objectives are equal. The calibration form's misfit (the budget's ``form`` source) is left
out of the search: it needs a simulated calibration of each candidate (seconds), and the
recommended form's misfit is a fraction of the noise floor.

The budget is evaluated on the grid of the stage that judges the candidate, never finer than
the budget's own 1° (:func:`budget_step_deg`): 3° in the search, 2° in the polish, 1° for the
verified design. Its worst cases lie on the workspace's edges and corners, which every grid
holds.

A Pareto front of white-noise resolution against drift sensitivity
(:mod:`~reflector_opt.optimiser._drift_front`) holds the common drift
(:func:`~reflector_opt.analysis._budget.drift_sensitivity`: the angle error of a 1 % change of
every sensor's light path, RMS over the workspace, the worse angle) below a limit,
``Problem.drift_limit_deg``: :func:`drift_constraint`.

Traded for less drift, the sensitivity can fall to the uniqueness limit (poses 1° apart at
least 3 σ_V apart), which the white-noise optimum never nears; in conditions, and with a drift
limit, the polish holds that limit at every pose and the verification's repair may tighten it
(:func:`steered_constraints`).
"""

import numpy as np

from reflector_opt.analysis._budget import BUDGET_STEP_DEG, drift_sensitivity, error_budget
from reflector_opt.analysis._resolution import UNIQUENESS_POSE_SEPARATION_DEG
from reflector_opt.design._conditions import Conditions
from reflector_opt.optimiser._candidates import surface_variants
from reflector_opt.optimiser._constraints import Constraint
from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import OBJECTIVES


def search_conditions(objective, conditions):
    """The operating conditions a search judges its candidates in (None: white noise).

    Parameters
    ----------
    objective : str
        One of :data:`~reflector_opt.util._limits.OBJECTIVES`.
    conditions : reflector_opt.design._conditions.Conditions or None
        The conditions stated, if any.

    Returns
    -------
    reflector_opt.design._conditions.Conditions or None
        ``conditions`` (the defaults where None) for ``"in-use"``, None for ``"resolution"``.

    Raises
    ------
    InputError
        An objective not in :data:`~reflector_opt.util._limits.OBJECTIVES`.
    """
    if objective not in OBJECTIVES:
        raise InputError(f"objective: {objective!r} is not one of {', '.join(OBJECTIVES)}")
    if objective == "resolution":
        return None
    return Conditions() if conditions is None else conditions


#: Name of the drift limit among a candidate's constraints.
DRIFT_CONSTRAINT = "drift_rms_deg"
#: Name of the uniqueness limit (:mod:`~reflector_opt.optimiser._constraints`).
SEPARATION_CONSTRAINT = "separation_sigma"
#: Relative light-path change of the drift sensitivity (1 %).
DRIFT_CHANGE = 0.01
#: A drift violation of this many degrees counts as 1 in the penalty.
DRIFT_SCALE_DEG = 0.1


def budget_step_deg(step_deg):
    """The budget's grid for a stage judging on ``step_deg``: that grid, at least 1°, degrees.

    Parameters
    ----------
    step_deg : float
        The stage's pose grid, degrees.

    Returns
    -------
    float
    """
    return max(float(step_deg), BUDGET_STEP_DEG)


def pose_totals(budget):
    """Root-sum-square of every source's worst-scenario error at each pose, per angle.

    Parameters
    ----------
    budget : reflector_opt.analysis._budget.ErrorBudget

    Returns
    -------
    numpy.ndarray
        Shape (n_pitch, n_roll, 2): pitch and roll, degrees (the noise at 1σ).
    """
    return np.sqrt(np.sum(np.stack(list(budget.maps.values())) ** 2, axis=0))


def worst_totals(budget):
    """``(T_γ, T_α)``: the largest total error over the workspace, per angle, degrees.

    Parameters
    ----------
    budget : reflector_opt.analysis._budget.ErrorBudget

    Returns
    -------
    (float, float)
        Their larger is ``budget.worst_case_deg``.
    """
    totals = pose_totals(budget)
    return float(totals[..., 0].max()), float(totals[..., 1].max())


def median_total_deg(budget):
    """The median over the workspace's poses of the total error, the worse angle at each, degrees.

    Parameters
    ----------
    budget : reflector_opt.analysis._budget.ErrorBudget

    Returns
    -------
    float
        What half the poses stay below (:func:`pose_totals`, the noise at 1σ).
    """
    return float(np.median(pose_totals(budget).max(axis=-1)))


def rms_total_deg(budget):
    """The RMS over the workspace's poses of the total error in use, the worse angle at each.

    Parameters
    ----------
    budget : reflector_opt.analysis._budget.ErrorBudget

    Returns
    -------
    float
        sqrt(mean over poses of max(T_γ, T_α)²), degrees, with T the root-sum-square of every
        source's worst-scenario error at the pose
        (:func:`pose_totals`, the noise at 1σ).
    """
    return float(np.sqrt(np.mean(pose_totals(budget).max(axis=-1) ** 2)))


def worst_budget(problem, design, step_deg, objective):
    """The error budget of the design's worst surface in the problem's conditions.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
        Its ``conditions`` (not None) and specular fractions.
    design : reflector_opt.design._design.Design
    step_deg : float
        The judging stage's pose grid, degrees (the budget's is :func:`budget_step_deg`).
    objective : callable
        ``objective(pitch_deg, roll_deg)``: the objective of the worst totals.

    Returns
    -------
    (float, reflector_opt.analysis._budget.ErrorBudget)
        The largest objective over the specular fractions and the budget that gives it.
    """
    step = budget_step_deg(step_deg)
    variants = surface_variants(problem, design)
    budgets = (error_budget(v, problem.conditions, step_deg=step) for v in variants)
    return max(((objective(*worst_totals(b)), b) for b in budgets), key=lambda pair: pair[0])


def common_drift_deg(design, step_deg=BUDGET_STEP_DEG):
    """The angle error of a 1 % change of every sensor's light path: the worse angle's RMS.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    step_deg : float, optional
        Grid step, degrees.

    Returns
    -------
    float
        Degrees per 1 % (:func:`~reflector_opt.analysis._budget.drift_sensitivity`, ``common``).
    """
    common = drift_sensitivity(design, change=DRIFT_CHANGE, step_deg=step_deg)["common"]
    return float(max(common.pitch_rms_deg, common.roll_rms_deg))


def drift_constraint(problem, design, step_deg, tightening):
    """The common drift of the worst surface against ``problem.drift_limit_deg``.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
        With ``drift_limit_deg`` set.
    design : reflector_opt.design._design.Design
    step_deg : float
        The judging stage's pose grid, degrees (the drift's is :func:`budget_step_deg`).
    tightening : mapping of str to float
        Extra margin demanded of named constraints, degrees for this one.

    Returns
    -------
    Constraint
        ``drift_rms_deg``: value at most the limit (less its tightening).
    """
    step = budget_step_deg(step_deg)
    value = max(common_drift_deg(v, step) for v in surface_variants(problem, design))
    limit = problem.drift_limit_deg - tightening.get(DRIFT_CONSTRAINT, 0.0)
    return Constraint(DRIFT_CONSTRAINT, value, limit, True, "°", DRIFT_SCALE_DEG)


def steered_constraints(problem):
    """The constraints beyond the smooth ones that the polish holds and the repair tightens.

    In operating conditions, or with a drift limit, the optimum trades sensitivity for less
    drift and can sit on the uniqueness limit (``separation_sigma``), which the white-noise
    optimum never nears: the polish holds its first-order estimate at every pose
    (:func:`separation_margins`), and the verification's repair may tighten it, as it may the
    drift limit. None for a white-noise problem, whose runs stay as they were.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem

    Returns
    -------
    tuple of str
    """
    if problem.conditions is None and problem.drift_limit_deg is None:
        return ()
    return (SEPARATION_CONSTRAINT, DRIFT_CONSTRAINT)


def separation_margins(problem, metrics, tightening):
    """First-order voltage separation of poses 1° apart at every pose, as scaled margins.

    With JᵀJ's eigenvalues λ₋ ≤ λ₊, the Cramér–Rao resolutions give
    σ_γ² + σ_α² = σ_V² (1/λ₋ + 1/λ₊) and the condition number κ² = λ₊/λ₋, so the least
    voltage change of a 1° step, in σ_V, is ``1°·sqrt(λ₋)/σ_V = 1°·sqrt((1 + κ⁻²)/(σ_γ² + σ_α²))``
    — the local estimate the search's uniqueness check takes at its worst pose
    (:func:`reflector_opt.optimiser._fused_objective.judge_poses`), here at every pose.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
        Its ``min_separation_sigma`` k.
    metrics : reflector_opt.analysis._metrics.DesignMetrics
    tightening : mapping of str to float
        Extra σ_V demanded of ``separation_sigma``.

    Returns
    -------
    numpy.ndarray
        ``(separation − k − tightening) / max(k, 1)`` at every pose, flattened (−1 where J
        is singular).
    """
    res2 = metrics.resolution_pitch_deg**2 + metrics.resolution_roll_deg**2
    with np.errstate(divide="ignore", invalid="ignore"):
        local = UNIQUENESS_POSE_SEPARATION_DEG * np.sqrt((1.0 + metrics.condition**-2) / res2)
    limit = problem.min_separation_sigma + tightening.get(SEPARATION_CONSTRAINT, 0.0)
    margin = (local - limit) / max(problem.min_separation_sigma, 1.0)
    return np.where(np.isfinite(margin), margin, -1.0).ravel()


#: Relative difference below which two poses' totals are the same worst (rounding: 1e-15).
TIE_RTOL = 1e-9


def binding_sources(budget):
    """Each source's error where the total is worst, largest first (the zero ones left out).

    Parameters
    ----------
    budget : reflector_opt.analysis._budget.ErrorBudget

    Returns
    -------
    dict
        ``{"pose_deg": [pitch, roll], "angle": "pitch" or "roll", "total_deg": …,
        "sources_deg": {source: error, …}, "shares": {source: share of the total's
        square, …}}``.
    """
    totals = pose_totals(budget)
    # The first worst pose in the grid's order among those within rounding of the worst: a
    # mirror-symmetric design ties at mirrored poses, and the last bits must not pick one.
    worst = np.flatnonzero(totals.ravel() >= np.max(totals) * (1.0 - TIE_RTOL))[0]
    i, j, k = np.unravel_index(int(worst), totals.shape)
    at = {name: float(m[i, j, k]) for name, m in budget.maps.items() if m[i, j, k] > 0.0}
    ordered = dict(sorted(at.items(), key=lambda item: -item[1]))
    total = float(totals[i, j, k])
    return {
        "pose_deg": [float(budget.pitch_deg[i, j]), float(budget.roll_deg[i, j])],
        "angle": ("pitch", "roll")[k],
        "total_deg": total,
        "sources_deg": ordered,
        "shares": {name: (e / total) ** 2 for name, e in ordered.items()},
    }
