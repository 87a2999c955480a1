"""Seeded global search, local polish and fine-grid verification of a design.

1. Differential evolution (``scipy.optimize.differential_evolution``, ``best1bin``,
   Latin-hypercube start, ``updating="deferred"`` so that one or several worker processes give
   the same result) over the free design variables, on a coarse pose grid (this module).
2. A local polish by SLSQP on the epigraph form of the worst case
   (:mod:`~reflector_opt.optimiser._polish`), from the best member, then from the polished
   point's image with the geometry mirrored in the unit's xy-plane (see
   :data:`~reflector_opt.optimiser._variables.Z_MIRRORED`: the objective has two similar basins
   and the population settles in one of them) and, when the pair's azimuth or across offset
   is searched, from the mirror-symmetric layouts of both; the best point is kept.
   The search only has to find the right basin: the polish finds its bottom.
3. Verification on the workspace grid (0.1°), then of the printed parts' walls by the CAD
   export's own rules (:mod:`~reflector_opt.optimiser._verify`). If a per-pose constraint fails
   there (it was met only on the coarser grid) it is tightened; if a printed wall is too thin,
   the walls become exact linear constraints of the polish; the polish is repeated, up to a
   few times; a design is returned only once it passes, else the run ends with an error
   naming the constraint.

Candidates are judged by the fused evaluation (:mod:`~reflector_opt.optimiser._fused_objective`)
where it applies.

The same seed gives the same design. With ``starts`` > 1 several searches, each polished,
run from seeds derived from the seed, on local processes or a Dask cluster, and the best is
verified: the same seed gives the same design wherever they run. The search and the polish
keep BLAS to one thread (``threadpoolctl``), since the order of a threaded BLAS's sums, and
so the last bits of SLSQP's steps, depends on the thread count.
"""

import contextlib
import dataclasses
import math
import time
from dataclasses import dataclass
from typing import Annotated

import numpy as np
from msgspec import Meta
from scipy.optimize import differential_evolution
from threadpoolctl import threadpool_limits

from reflector_opt.optimiser._evaluation import PENALTY
from reflector_opt.optimiser._fused_objective import search_objective
from reflector_opt.optimiser._polish import polish_from_starts
from reflector_opt.optimiser._problem import Problem
from reflector_opt.optimiser._result import OptimisationResult
from reflector_opt.optimiser._variables import values_from_vector
from reflector_opt.optimiser._verify import verify
from reflector_opt.util import _schema as schema
from reflector_opt.util._declared import Seed, Workers, option
from reflector_opt.util._errors import InputError, NoDesignError
from reflector_opt.util._limits import (
    MAX_ANGLE_DEG,
    MAX_POSE_EVALUATIONS,
    MAX_STARTS,
    check_count,
    check_size,
)
from reflector_opt.util._pools import local_processes, ordered_map, run_batches
from reflector_opt.util._progress import Phases, scaled


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

    popsize: int = 6
    maxiter: int = 20
    tol: float = 1e-2
    grid_step_deg: float = 3.0
    polish_step_deg: float = 2.0
    polish_maxiter: int = 60
    workers: int = 2

    def __post_init__(self):
        """Check every field against ``[search]``'s declaration
        (:class:`SearchTable`), the one place its ranges are stated."""
        schema.convert(dataclasses.asdict(self), SearchTable, where="search")


#: A pose grid step, degrees.
_Step = Annotated[float, Meta(gt=0, le=MAX_ANGLE_DEG, description="a pose grid step, degrees")]


class SearchTable(schema.Table):
    """``[search]``: the random seed and the search budget."""

    # Each key's range is declared here once: SearchBudget is checked against it too.

    seed: Seed = 0
    popsize: Annotated[int, Meta(ge=1, le=1000, description="population per variable")] = (
        SearchBudget.popsize
    )
    maxiter: Annotated[int, Meta(ge=1, le=10_000, description="most generations")] = (
        SearchBudget.maxiter
    )
    tol: Annotated[float, Meta(gt=0, le=1e6, description="population spread to stop")] = (
        SearchBudget.tol
    )
    grid_step_deg: _Step = SearchBudget.grid_step_deg
    polish_step_deg: _Step = SearchBudget.polish_step_deg
    polish_maxiter: Annotated[int, Meta(ge=0, le=10_000, description="0: no polish")] = (
        SearchBudget.polish_maxiter
    )
    workers: option(Workers, "worker processes of the search") = SearchBudget.workers


def check_search_work(problem, budget, starts=1):
    """Refuse a search whose pose grids or evaluations exceed the limits of one run.

    Parameters
    ----------
    problem : Problem
    budget : SearchBudget
    starts : int, optional
        Independent searches of a multi-start run.

    Returns
    -------
    int
        Model evaluations at a pose of the global search at most (every candidate of every
        generation of every start on the grid and its 5-pose Jacobian stencil). Raises
        :class:`~reflector_opt.util._errors.InputError` naming the parameters.
    """
    workspace = problem.workspace
    poses = 5 * workspace.check_step(budget.grid_step_deg, "search.grid_step_deg")
    workspace.check_step(budget.polish_step_deg, "search.polish_step_deg")
    candidates = starts * budget.popsize * len(problem.free_names) * (budget.maxiter + 1)
    return check_size(
        candidates * poses,
        f"search.popsize, search.maxiter and starts ({candidates:,} candidates × {poses:,} "
        "poses each)",
        MAX_POSE_EVALUATIONS,
        "model evaluations",
    )


#: The work of one optimisation's phases, s (the defaults, one start, two workers): the
#: search with its polish, then the verification with its repairs.
SEARCH_WORK = {"search": 6.4, "verify": 4.6}
#: The search's generations' share of the search with its polish (the polish takes the rest).
GENERATIONS_SHARE = 0.8


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
                "spread": spread if math.isfinite(spread) else None,
            }
        )
        if self.progress is not None:
            best = intermediate_result.fun
            found = f"best {best:.4g}°" if best < PENALTY else "no feasible design yet"
            self.progress(
                generation / self.budget.maxiter, f"search generation {generation}, {found}"
            )
        return spread <= self.budget.tol


def _global_search(objective, lower, upper, seed, budget, callback, x0=None, map_=map):
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
        "workers": 1 if map_ is map else map_,  # 1, scipy's default: in this process
    }
    return differential_evolution(objective, list(zip(lower, upper, strict=True)), **kwargs)


@contextlib.contextmanager
def _worker_pool(problem, budget, lower, upper, used=True):
    """``budget.workers`` local worker processes for one start's search, polish and
    verification (:func:`~reflector_opt.util._pools.local_processes`).

    Yields None for one worker (all the work in this process) or when not ``used``. One
    evaluation here first loads the compiled kernels (numba's cache) into this process, and
    the workers, forked on Linux, inherit them instead of each loading them again.
    """
    if budget.workers == 1 or not used:
        yield None
        return
    search_objective(problem, budget.grid_step_deg)(0.5 * (lower + upper))
    with local_processes(budget.workers)() as pool:
        yield pool


def _baseline_evaluation(problem):
    """The built-in default design judged under ``problem`` on its workspace grid, or None
    if it is not a valid design there."""
    try:
        return problem.evaluate_design(problem.baseline_design())
    except InputError:
        return None


def start_seeds(seed, starts):
    """Seeds of the independent starts of a multi-start run.

    One start uses ``seed`` itself (the single search); more use the seeds of
    ``numpy.random.SeedSequence(seed).spawn(starts)``, so the same seed gives the same starts
    wherever they run.

    Parameters
    ----------
    seed : int
    starts : int

    Returns
    -------
    list of int
    """
    if starts == 1:
        return [seed]
    return [int(s.generate_state(1)[0]) for s in np.random.SeedSequence(seed).spawn(starts)]


def _search_and_polish(problem, budget, lower, upper, x0, seed, progress=None, map_=map):
    """One start: the global search from ``seed`` and the polish of its best member.

    ``map_`` (ordered like the builtin ``map``, e.g. a worker pool's) evaluates the search's
    population and the polish's forward differences.

    Returns
    -------
    dict
        ``x`` (the polished point), ``score`` (its penalised objective on the polish grid),
        ``feasible``, ``failure`` (why the search's best is infeasible, or None), the
        convergence ``history``, the evaluations of the ``search`` and the ``polish`` and
        their ``seconds``.
    """
    names = problem.free_names
    t0 = time.perf_counter()
    generations = None if progress is None else scaled(progress, 0.0, GENERATIONS_SHARE)
    recorder = _Monitor(budget, generations)
    coarse = search_objective(problem, budget.grid_step_deg)
    search = _global_search(coarse, lower, upper, seed, budget, recorder, x0, map_)
    best = coarse.evaluate_values(values_from_vector(names, search.x, problem.fixed_values))
    out = {
        "seed": seed,
        "history": recorder.history,
        "search": int(search.nfev) + 1,
        "search_seconds": time.perf_counter() - t0,
        "feasible": best.feasible,
        "failure": None if best.feasible else best.describe_failure(),
        "x": search.x,
        "score": best.penalised,
        "polish": 0,
    }
    if not best.feasible:
        return out
    t0 = time.perf_counter()
    if progress is not None:
        progress(GENERATIONS_SHARE, "polishing")
    x, used = polish_from_starts(problem, search.x, lower, upper, budget, map_)
    judge = search_objective(problem, budget.polish_step_deg)
    out.update(x=x, score=judge(x), polish=used + 1, polish_seconds=time.perf_counter() - t0)
    return out


def _starts(problem, budget, lower, upper, x0, seed, starts, executor, progress, map_):
    """Each start's :func:`_search_and_polish`: one in this process (with ``map_``), more as
    tasks of ``executor`` (default ``budget.workers`` local processes)."""
    if starts == 1 and executor is None:
        return [_search_and_polish(problem, budget, lower, upper, x0, seed, progress, map_)]
    if progress is not None:
        progress(0.0, f"{starts} searches")
    factory = local_processes(budget.workers) if executor is None else executor
    args = (problem, dataclasses.replace(budget, workers=1), lower, upper, x0)
    seeds = [[s] for s in start_seeds(seed, starts)]
    runs = run_batches(_run_starts, args, seeds, factory, progress=progress)
    return [run for batch in runs for run in batch]


def _run_starts(args, batch):
    """Worker side of a multi-start run: :func:`_search_and_polish` for each seed of a batch."""
    problem, budget, lower, upper, x0 = args
    with threadpool_limits(limits=1):
        return [_search_and_polish(problem, budget, lower, upper, x0, seed) for seed in batch]


def optimise(
    problem=None, *, seed=0, budget=None, progress=None, initial=None, starts=1, executor=None
):
    """Find the design with the best worst-case resolution that meets every constraint.

    Parameters
    ----------
    problem : Problem, optional
        Part, workspace, envelope, noise, bounds, weights, limits, conditions (built-in).
    seed : int, optional
        Seed of the global search; the same seed gives the same design.
    budget : SearchBudget, optional
        Population, generations, grids and workers.
    progress : callable, optional
        ``progress(fraction, message)`` (the search, polish and verification by their work).
    initial : mapping of str to float, optional
        A design (its variables) to place in the initial population, e.g. a previous
        optimum; it is clipped to the bounds.
    starts : int, optional
        Independent searches, each polished, from the seeds :func:`start_seeds` derives from
        ``seed``; the best polished point is verified. With more than one they run as tasks
        of ``executor`` (each search in one process), and the result does not depend on
        where they ran.
    executor : callable, optional
        Executor factory of :mod:`reflector_opt.util._pools` for the starts (e.g.
        ``dask_cluster(address)``); default ``budget.workers`` local processes.

    Returns
    -------
    OptimisationResult
        Raises :class:`~reflector_opt.util._errors.InputError` naming the constraint that no design
        within the bounds meets, or that the returned design would fail on the workspace grid.
    """
    problem = Problem() if problem is None else problem
    budget = SearchBudget() if budget is None else budget
    lower, upper, x0 = _checked_bounds(problem, budget, starts, initial)
    seconds, evaluations = {}, {}
    with threadpool_limits(limits=1), contextlib.ExitStack() as stack:
        alone = starts == 1 and executor is None  # one search here: a pool for its work
        pool = stack.enter_context(_worker_pool(problem, budget, lower, upper, alone))
        map_ = map if pool is None else ordered_map(pool, budget.workers)
        t0 = time.perf_counter()
        found = (phases := Phases(progress, SEARCH_WORK))("search")
        runs = _starts(problem, budget, lower, upper, x0, seed, starts, executor, found, map_)
        seconds["search"] = time.perf_counter() - t0
        chosen, polish_seconds = _best_run(runs, seconds, evaluations)
        # the default design's evaluation, for the comparison, on a worker meanwhile
        default = None if pool is None else pool.submit(_baseline_evaluation, problem)
        t0 = time.perf_counter()
        final, tightening = _verified(
            problem, chosen["x"], lower, upper, budget, phases("verify"), evaluations, map_
        )
        seconds["polish_and_verify"] = polish_seconds + time.perf_counter() - t0
        baseline = _baseline_evaluation(problem) if default is None else default.result()
    if baseline is not None:
        evaluations["baseline"] = 1
    result = OptimisationResult(
        None, final, baseline, seed, chosen["history"], evaluations, seconds, budget, tightening
    )
    return dataclasses.replace(result, design=final.design.replace(predicted=result.predicted()))


def _verified(problem, x, lower, upper, budget, progress, evaluations, map_):
    """:func:`~reflector_opt.optimiser._verify.verify` of ``x``, or InputError naming what the
    design it ends with fails."""
    evaluations["verify"] = 0
    final, tightening = verify(problem, x, lower, upper, budget, progress, evaluations, map_)
    if not final.feasible:
        raise NoDesignError(
            f"no design passed verification on the {problem.workspace.step_deg}° grid: "
            + final.describe_failure()
        )
    return final, tightening


def _checked_bounds(problem, budget, starts, initial):
    """The free variables' bounds and the clipped initial point (None without one), once the
    starts, the variables and the search's work are checked."""
    check_count(starts, "starts", 1, MAX_STARTS)
    names = problem.free_names
    if not names:
        raise InputError("bounds: every design variable is fixed; nothing to optimise")
    check_search_work(problem, budget, starts)
    lower, upper = np.array([problem.search_bounds[n] for n in names]).T
    x0 = None if initial is None else np.clip([float(initial[n]) for n in names], lower, upper)
    return lower, upper, x0


def _best_run(runs, seconds, evaluations):
    """The best feasible start (the first of equals: the same wherever they ran) and its
    polish's seconds; the runs' evaluations counted, and with one run in this process its own
    split of the time. Raises InputError naming the closest failure if none is feasible."""
    evaluations["search"] = sum(r["search"] for r in runs)
    evaluations["polish"] = sum(r["polish"] for r in runs)
    feasible = [r for r in runs if r["feasible"]]
    if not feasible:
        raise NoDesignError(
            "no design within the bounds meets the constraints; the closest: " + runs[0]["failure"]
        )
    chosen = min(feasible, key=lambda r: r["score"])
    if len(runs) > 1:
        return chosen, 0.0
    seconds["search"] = chosen["search_seconds"]
    return chosen, chosen.get("polish_seconds", 0.0)
