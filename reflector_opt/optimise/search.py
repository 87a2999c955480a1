"""Seeded global search, local polish and fine-grid verification of a design.

1. Differential evolution (``scipy.optimize.differential_evolution``, ``best1bin``,
   Latin-hypercube start, ``updating="deferred"`` so that one or several worker processes give
   the same result) over the free design variables, on a coarse pose grid.
2. A local polish by SLSQP on the epigraph form of the worst case (see :func:`_polish`),
   from the best member, then from the polished point's image with the geometry mirrored in
   the unit's xy-plane (see :data:`~reflector_opt.optimise.variables.Z_MIRRORED`: the
   objective has two similar basins and the population settles in one of them) and, when
   the pair's azimuth or across offset is searched, from the mirror-symmetric layouts of
   both; the best point is kept.
   The search only has to find the right basin: the polish finds its bottom.
3. Verification on the workspace grid (0.1°), then of the printed parts' walls by the CAD
   export's own rules (:meth:`~reflector_opt.optimise.problem.Problem.check_printed`). If a
   per-pose constraint fails there (it was met only on the coarser grid) or a printed wall
   is too thin, a smooth constraint is tightened and the polish repeated, up to a few times;
   a design is returned only once it passes, else the run ends with an error naming the
   constraint.

The same seed gives the same design.
"""

from __future__ import annotations

import dataclasses
import math
import multiprocessing
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import differential_evolution, minimize

from reflector_opt.optimise.problem import (
    PENALTY,
    PRINTED_WALL,
    PRINTED_WALL_PROXIES,
    SMOOTH_CONSTRAINTS,
    Problem,
)
from reflector_opt.optimise.variables import symmetric_layout, values_from_vector, z_mirror
from reflector_opt.util.errors import InputError

__all__ = ["OptimisationResult", "SearchBudget", "optimise"]

#: Rounds of tighten-and-polish before a design that fails verification is given up.
REPAIR_ROUNDS = 4

#: Forward-difference step of the polish, in units of each variable's range.
POLISH_STEP = 1e-6

#: The polish keeps every scaled margin at least this far inside its limit, so that a
#: constraint active at the optimum is met, not missed by rounding.
POLISH_CUSHION = 1e-6


@dataclass(frozen=True)
class SearchBudget:
    """How much work the search may do.

    Parameters
    ----------
    popsize : int
        Population size per free variable (scipy's ``popsize``).
    maxiter : int
        Most generations of differential evolution.
    tol : float
        The search stops when every member is feasible and the population's objectives have
        std/mean at most this.
    grid_step_deg : float
        Pose grid of the global search, degrees.
    polish_step_deg : float
        Pose grid of the local polish, degrees.
    polish_maxiter : int
        Most SLSQP iterations of the polish from each of its two starts (0: no polish);
        each costs one evaluation per free variable plus its line search.
    workers : int
        Processes evaluating the population (1: in this process).
    """

    popsize: int = 10
    maxiter: int = 40
    tol: float = 1e-2
    grid_step_deg: float = 3.0
    polish_step_deg: float = 2.0
    polish_maxiter: int = 60
    workers: int = 2

    def __post_init__(self):
        for key in ("popsize", "maxiter", "workers"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise InputError(f"search.{key}: must be a whole number ≥ 1, got {value!r}")
        if isinstance(self.polish_maxiter, bool) or not isinstance(self.polish_maxiter, int):
            raise InputError("search.polish_maxiter: must be a whole number")
        if self.polish_maxiter < 0:
            raise InputError("search.polish_maxiter: must be ≥ 0")
        for key in ("tol", "grid_step_deg", "polish_step_deg"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise InputError(f"search.{key}: expected a number, got {value!r}")
            if not (math.isfinite(value) and value > 0):
                raise InputError(f"search.{key}: must be positive, got {value}")


class PenalisedObjective:
    """``x -> Evaluation.penalised`` over the free variables; picklable for worker processes.

    Parameters
    ----------
    problem : Problem
    step_deg : float
        Pose grid step, degrees.
    """

    def __init__(self, problem, step_deg):
        self.problem = problem
        self.step_deg = float(step_deg)
        self.names = problem.free_names
        self.fixed = problem.fixed_values

    def values(self, x):
        """``{name: value}`` for every variable at the free-variable vector ``x``."""
        return values_from_vector(self.names, x, self.fixed)

    def evaluate(self, x):
        """The full :class:`Evaluation` at ``x``."""
        return self.problem.evaluate(self.values(x), self.step_deg, checked=False)

    def __call__(self, x):
        return self.evaluate(x).penalised


@dataclass(frozen=True)
class OptimisationResult:
    """What :func:`optimise` found.

    Attributes
    ----------
    design : reflector_opt.design.design.Design
        The optimised design on the workspace grid, with ``predicted`` filled in.
    evaluation : Evaluation
        Its metrics and constraints on the workspace grid (0.1°).
    baseline : Evaluation or None
        The built-in default geometry under the same part, envelope and noise (None if that
        geometry is not valid here).
    seed : int
    history : list of dict
        Per generation: ``generation``, ``best`` (penalised objective on the search grid) and
        ``spread`` (std/mean of the population's objectives; None while some are infeasible).
    evaluations : dict
        Objective (forward-model) evaluations per stage: ``search``, ``polish``, ``verify``
        and ``baseline`` (each on that stage's pose grid).
    seconds : dict
        Wall time per stage.
    budget : SearchBudget
    tightening : dict
        Extra constraint margins the repair needed (empty if none).
    """

    design: object
    evaluation: object
    baseline: object
    seed: int
    history: list
    evaluations: dict
    seconds: dict
    budget: SearchBudget
    tightening: dict = field(default_factory=dict)

    @property
    def objective(self):
        """Objective on the workspace grid, degrees."""
        return self.evaluation.objective

    @property
    def metrics(self):
        """:class:`~reflector_opt.analysis.metrics.DesignMetrics` on the workspace grid."""
        return self.evaluation.metrics

    @property
    def improvement(self):
        """Baseline over optimised worst-case resolution (pitch, roll, overall), or None."""
        if self.baseline is None or self.baseline.metrics is None:
            return None
        base, opt = self.baseline.metrics, self.metrics
        return {
            "pitch": _ratio(base.worst_pitch_deg, opt.worst_pitch_deg),
            "roll": _ratio(base.worst_roll_deg, opt.worst_roll_deg),
            "worst": _ratio(base.worst_resolution_deg, opt.worst_resolution_deg),
        }

    def predicted(self):
        """The ``predicted`` block of ``design.json``: metrics, margins, search record."""
        out = {
            "objective_deg": self.objective,
            "metrics": self.metrics.to_dict(),
            "constraints": self.evaluation.constraints_dict(),
            "optimiser": {
                "seed": self.seed,
                "evaluations": dict(self.evaluations),
                "generations": len(self.history),
                "seconds": {k: round(v, 3) for k, v in self.seconds.items()},
                "budget": self.budget.__dict__.copy(),
                "variables": dict(self.evaluation.values),
                "repair_tightening": dict(self.tightening),
            },
        }
        if self.baseline is not None and self.baseline.metrics is not None:
            out["baseline"] = {
                "design": "built-in default geometry, same part, envelope and noise",
                "objective_deg": _finite(self.baseline.objective),
                "metrics": self.baseline.metrics.to_dict(),
                "feasible": self.baseline.feasible,
            }
            out["improvement"] = self.improvement
        return out


def _ratio(a, b):
    if not (math.isfinite(a) and math.isfinite(b)) or b <= 0:
        return None
    return a / b


def _finite(x):
    return float(x) if math.isfinite(x) else None


class _Monitor:
    """Record the convergence history, report progress and decide when the search has converged.

    scipy's own test, std(energies) ≤ tol·|mean(energies)|, would stop a population that is
    still all infeasible (energies ≈ PENALTY, tiny relative spread); this one waits until
    every member is feasible.
    """

    def __init__(self, budget, progress):
        self.budget = budget
        self.progress = progress
        self.history = []

    def __call__(self, intermediate_result):
        energies = intermediate_result.population_energies
        all_feasible = bool(np.all(energies < PENALTY))
        spread = float(np.std(energies) / abs(np.mean(energies))) if all_feasible else math.inf
        generation = len(self.history) + 1
        self.history.append(
            {
                "generation": generation,
                "best": float(intermediate_result.fun),
                "spread": _finite(spread),
            }
        )
        if self.progress is not None:
            best = intermediate_result.fun
            found = f"best {best:.4g}°" if best < PENALTY else "no feasible design yet"
            self.progress(
                generation / self.budget.maxiter, f"search generation {generation}, {found}"
            )
        return spread <= self.budget.tol


def _global_search(objective, lower, upper, seed, budget, callback, x0=None):
    kwargs = {
        "strategy": "best1bin",
        "maxiter": budget.maxiter,
        "popsize": budget.popsize,
        "tol": 0.0,  # convergence is decided by _Monitor
        "atol": 0.0,
        "mutation": (0.5, 1.0),
        "recombination": 0.9,
        "rng": np.random.default_rng(seed),
        "callback": callback,
        "polish": False,
        "init": "latinhypercube",
        "updating": "deferred",
        "x0": x0,
    }
    bounds = list(zip(lower, upper, strict=True))
    if budget.workers == 1:
        return differential_evolution(objective, bounds, **kwargs)
    with multiprocessing.Pool(budget.workers) as pool:
        return differential_evolution(objective, bounds, workers=pool.map, **kwargs)


class _PoseFields:
    """Per-pose resolution and constraint margins at normalised points, cached per point."""

    def __init__(self, problem, lower, upper, step_deg, tightening):
        self.problem = problem
        self.lower, self.span = lower, upper - lower
        self.step_deg = step_deg
        self.tightening = tightening
        self.cache = {}

    def __call__(self, u):
        key = u.tobytes()
        if key not in self.cache:
            x = np.clip(self.lower + u * self.span, self.lower, self.lower + self.span)
            values = values_from_vector(self.problem.free_names, x, self.problem.fixed_values)
            e = self.problem.evaluate(
                values, self.step_deg, tightening=self.tightening, checked=False
            )
            fields = None
            if e.metrics is not None and e.metrics.sensitive:
                resolution, margins = self.problem.pose_margins(e, self.tightening)
                fields = (resolution, margins - POLISH_CUSHION)
            self.cache[key] = fields
        return self.cache[key]


def _polish(problem, x0, lower, upper, step_deg, maxiter, tightening=None):
    """SLSQP on the epigraph form of the worst case, from x0.

    ``minimise t  subject to  σ_γ(p) ≤ t, σ_α(p) ≤ t  and  m_k(p) ≥ 0  at every pose p``,
    with m_k the margins of the smooth constraints (distance window, reflector envelope,
    wall). Each is a smooth function of the design, so a gradient method converges to the
    local optimum precisely where a simplex on the worst case stalls at its kinks. The
    variables are scaled to [0, 1]; derivatives are forward differences, one evaluation per
    free variable.

    Returns
    -------
    (numpy.ndarray, int)
        The point reached and the evaluations used.
    """
    fields = _PoseFields(problem, lower, upper, step_deg, tightening or {})
    u0 = (np.asarray(x0, dtype=float) - lower) / (upper - lower)
    start = fields(u0)
    if start is None or maxiter == 0:
        return np.asarray(x0, dtype=float), len(fields.cache)
    scale = float(start[0].max())
    n_res, n_all = start[0].size, start[0].size + start[1].size

    def constraints(z):
        f = fields(z[:-1])
        if f is None:
            return np.full(n_all, -1.0)
        return np.concatenate([z[-1] - f[0] / scale, f[1]])

    def constraints_jacobian(z):
        u, c0 = z[:-1], constraints(z)
        jac = np.zeros((n_all, z.size))
        for k in range(u.size):
            du = POLISH_STEP if u[k] + POLISH_STEP <= 1.0 else -POLISH_STEP
            uk = u.copy()
            uk[k] += du
            jac[:, k] = (constraints(np.append(uk, z[-1])) - c0) / du
        jac[:n_res, -1] = 1.0
        return jac

    last = np.eye(u0.size + 1)[-1]
    res = minimize(
        lambda z: z[-1],
        np.append(u0, 1.0),
        jac=lambda z: last,
        method="SLSQP",
        bounds=[(0.0, 1.0)] * u0.size + [(0.0, None)],
        constraints=[{"type": "ineq", "fun": constraints, "jac": constraints_jacobian}],
        options={"maxiter": maxiter, "ftol": 1e-10},
    )
    return np.clip(lower + res.x[:-1] * (upper - lower), lower, upper), len(fields.cache)


def _other_basins(problem, x, lower, upper):
    """x's z-mirror image and, if the pair's symmetry is searched, the mirror-symmetric
    layouts of x and of its image; each clipped to the bounds, without x or repeats."""
    names = problem.free_names
    values = values_from_vector(names, x, problem.fixed_values)
    layouts = [values, z_mirror(values)]
    if {"sensor_azimuth_deg", "centre_across_mm"} & set(names):
        layouts += [symmetric_layout(v) for v in layouts]
    starts = [np.asarray(x, dtype=float)]
    for v in layouts[1:]:
        start = np.clip([v[n] for n in names], lower, upper)
        if not any(np.array_equal(start, s) for s in starts):
            starts.append(start)
    return starts[1:]


def _polish_from_starts(problem, x, lower, upper, budget):
    """Polish x, then polish from the other basins' images of the polished point.

    The image of a converged point lies near the bottom of the other basin, which the image
    of a rough search result may not. Returns the best of x and every polished point (judged
    on the polish grid) and the evaluations used.

    Returns
    -------
    (numpy.ndarray, int)
    """
    step, maxiter = budget.polish_step_deg, budget.polish_maxiter
    first, used = _polish(problem, x, lower, upper, step, maxiter)
    candidates = [np.asarray(x, dtype=float), first]
    for start in _other_basins(problem, first, lower, upper):
        point, n = _polish(problem, start, lower, upper, step, maxiter)
        candidates.append(point)
        used += n
    judge = PenalisedObjective(problem, step)
    scores = [judge(c) for c in candidates]
    return candidates[int(np.argmin(scores))], used + len(candidates)


def _repair_tightening(evaluation, tightening):
    """The tightening that steers the polish away from every failure of ``evaluation``.

    A failing smooth constraint is tightened by 1.5× its shortfall. A failing printed wall is
    steered by its proxy (:data:`~reflector_opt.optimise.problem.PRINTED_WALL_PROXIES`),
    tightened so that the proxy must move by 1.5× the wall's shortfall: past its present
    margin, which the polish would otherwise keep.

    Returns
    -------
    dict or None
        The new tightening, or None if some failure cannot be steered by the polish
        (uniqueness, fold, a wall fixed by the CAD parameters, no valid layout).
    """
    if evaluation.error is not None:
        return None
    constraints = {c.name: c for c in evaluation.constraints}
    out = dict(tightening)
    for c in evaluation.constraints:
        if c.met:
            continue
        if c.name in SMOOTH_CONSTRAINTS:
            out[c.name] = out.get(c.name, 0.0) + 1.5 * (-c.margin)
        elif c.name == PRINTED_WALL:
            for wall, mm in evaluation.printed_walls_mm.items():
                proxy = PRINTED_WALL_PROXIES.get(wall)
                if mm >= c.limit:
                    continue
                if proxy is None:
                    return None
                slack = max(constraints[proxy].margin, 0.0)
                out[proxy] = out.get(proxy, 0.0) + slack + 1.5 * (c.limit - mm)
        else:
            return None
    return out


def _verify(problem, x, lower, upper, budget, progress, evaluations):
    """Evaluate on the workspace grid and check the printed walls, repairing what fails.

    A per-pose constraint that fails on the workspace grid (it was met only on the coarser
    grid) or a printed wall below the minimum is repaired by tightening a smooth constraint
    and polishing again (:func:`_repair_tightening`), up to :data:`REPAIR_ROUNDS` times.

    Returns
    -------
    (Evaluation, dict)
        The final evaluation (feasible or not) and the tightening the repair applied.
    """
    tightening = {}
    for round_ in range(REPAIR_ROUNDS + 1):
        if progress is not None:
            progress(1.0, "verifying on the workspace grid")
        values = values_from_vector(problem.free_names, x, problem.fixed_values)
        final = problem.evaluate(values)
        evaluations["verify"] += 1
        if final.feasible:
            if progress is not None:
                progress(1.0, "checking the printed walls")
            final = problem.check_printed(final)
        if final.feasible or round_ == REPAIR_ROUNDS:
            break
        repaired = _repair_tightening(final, tightening)
        if repaired is None:
            break  # failing a constraint the polish cannot steer
        tightening = repaired
        x, n = _polish(
            problem, x, lower, upper, budget.polish_step_deg, budget.polish_maxiter, tightening
        )
        evaluations["polish"] += n
    return final, tightening


def optimise(problem=None, *, seed=0, budget=None, progress=None, initial=None):
    """Find the design with the best worst-case resolution that meets every constraint.

    Parameters
    ----------
    problem : Problem, optional
        Part, workspace, envelope, noise, bounds, weights and limits (default: built-in).
    seed : int, optional
        Seed of the global search; the same seed gives the same design.
    budget : SearchBudget, optional
        Population, generations, grids and workers.
    progress : callable, optional
        ``progress(fraction, message)``, called as the work advances.
    initial : mapping of str to float, optional
        A design (its variables) to place in the initial population, e.g. a previous
        optimum; it is clipped to the bounds.

    Returns
    -------
    OptimisationResult
        Raises :class:`~reflector_opt.util.errors.InputError` naming the constraint that no design
        within the bounds meets, or that the returned design would fail on the workspace grid.
    """
    problem = Problem() if problem is None else problem
    budget = SearchBudget() if budget is None else budget
    names = problem.free_names
    if not names:
        raise InputError("bounds: every design variable is fixed; nothing to optimise")
    lower = np.array([problem.search_bounds[n][0] for n in names])
    upper = np.array([problem.search_bounds[n][1] for n in names])
    x0 = None if initial is None else np.clip([float(initial[n]) for n in names], lower, upper)
    seconds, evaluations = {}, {}

    t0 = time.perf_counter()
    recorder = _Monitor(budget, progress)
    coarse = PenalisedObjective(problem, budget.grid_step_deg)
    search = _global_search(coarse, lower, upper, seed, budget, recorder, x0)
    best = coarse.evaluate(search.x)
    evaluations["search"] = int(search.nfev) + 1
    seconds["search"] = time.perf_counter() - t0
    if not best.feasible:
        raise InputError(
            "no design within the bounds meets the constraints; the closest: "
            + best.describe_failure()
        )

    t0 = time.perf_counter()
    if progress is not None:
        progress(1.0, "polishing")
    x, evaluations["polish"] = _polish_from_starts(problem, search.x, lower, upper, budget)
    evaluations["verify"] = 0
    final, tightening = _verify(problem, x, lower, upper, budget, progress, evaluations)
    seconds["polish_and_verify"] = time.perf_counter() - t0
    if not final.feasible:
        raise InputError(
            f"no design passed verification on the {problem.workspace.step_deg}° grid: "
            + final.describe_failure()
        )

    try:
        baseline = problem.evaluate_design(problem.baseline_design())
        evaluations["baseline"] = 1
    except InputError:
        baseline = None
    result = OptimisationResult(
        design=None,
        evaluation=final,
        baseline=baseline,
        seed=seed,
        history=recorder.history,
        evaluations=evaluations,
        seconds=seconds,
        budget=budget,
        tightening=tightening,
    )
    return dataclasses.replace(result, design=final.design.replace(predicted=result.predicted()))
