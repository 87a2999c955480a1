"""Robust design: a distance margin that covers the tolerances, and the yield of designs.

The optimiser's ``distance_margin_mm`` keeps every sensor's distance window that far inside
its usable range; a tolerance study (:func:`reflector_opt.tolerance.run_study`) measures how
much of that margin the built units lose. :func:`robust_optimise` closes the loop:

1. optimise with the configured margin;
2. run a Monte Carlo study of the result's geometry (the calibration is skipped: the window
   is pure geometry) and take a 95 % upper confidence bound on the ``coverage`` quantile of
   the margin lost from nominal to as built, the *required margin*
   (:func:`reflector_opt.tolerance._statistics.quantile_upper_bound`);
3. if the design's margin on the workspace grid covers the required margin, stop; else
   raise the margin constraint to it and optimise again, warm-started from the design;

up to ``max_rounds`` optimisations. Every study draws the same units (the tolerance run's
seed), so the rounds compare like with like and the same seeds give the same design.

:func:`front_yield` gives each feasible point of a Pareto front
(:func:`reflector_opt.optimiser._pareto.pareto_front`) its yield: the fraction of sampled
built units that meet the tolerance run's targets, with a 95 % Wilson interval.
"""

import dataclasses
import time
from dataclasses import dataclass
from typing import Annotated

import numpy as np
from msgspec import Meta

from reflector_opt.optimiser._problem import Problem
from reflector_opt.optimiser._studies import optimise_variants
from reflector_opt.tolerance._config import ToleranceConfig
from reflector_opt.tolerance._statistics import CONFIDENCE, COVERAGE
from reflector_opt.tolerance._study import run_study
from reflector_opt.util import _schema as schema
from reflector_opt.util._display import Summarised, fmt
from reflector_opt.util._errors import InputError
from reflector_opt.util._pools import local_processes, reused
from reflector_opt.util._progress import scaled

#: A design covers the required margin when its margin falls short of it by at most this,
#: mm: far below the Monte Carlo's own resolution of a quantile.
CONVERGENCE_MM = 1e-3


#: Most rounds of the robust loop (each a full optimisation and tolerance study).
MAX_ROUNDS = 100


@dataclass(frozen=True)
class RobustOptions:
    """How :func:`robust_optimise` iterates.

    Parameters
    ----------
    coverage : float
        Fraction of built units whose distance window the margin must cover, strictly
        between 0 and 1.
    max_rounds : int
        Most optimisations (the first one included) before the loop gives up.
    """

    coverage: float = COVERAGE
    max_rounds: int = 5

    def __post_init__(self):
        """Check every field against ``[robust]``'s declaration (:class:`RobustTable`), the
        one place its ranges are stated."""
        schema.convert(dataclasses.asdict(self), RobustTable)


class RobustTable(schema.Table):
    """``[robust]``: used with ``--tolerances``."""

    coverage: Annotated[
        float, Meta(gt=0, lt=1, description="fraction of built units the margin covers")
    ] = RobustOptions.coverage
    max_rounds: Annotated[int, Meta(ge=1, le=MAX_ROUNDS, description="most optimisations")] = (
        RobustOptions.max_rounds
    )


@dataclass(frozen=True, repr=False)
class RobustResult(Summarised):
    """What :func:`robust_optimise` found.

    Attributes
    ----------
    result : reflector_opt.optimiser.OptimisationResult
        The last round's optimisation; its design's ``predicted["robust"]`` records the
        rounds (:meth:`to_dict`).
    rounds : tuple of dict
        Per optimisation: ``round``, ``limit_mm`` (the margin the optimiser had to meet),
        ``margin_mm`` (the margin reached on the workspace grid), ``required_mm`` (the
        margin lost in ``coverage`` of the built units: the 95 % upper confidence bound, or
        with too few samples for it the sample quantile), ``required_estimate_mm`` (the
        sample quantile), ``required_confidence`` (0.95, or None), ``window_yield`` and
        ``window_yield_interval`` (95 % Wilson), ``objective_deg`` and the design
        ``variables``.
    converged : bool
        The last design's margin covers its required margin.
    options : RobustOptions
    tolerance : reflector_opt.tolerance._config.ToleranceConfig
    seconds : float
        Wall time of the whole loop (every optimisation and study), s.
    """

    result: object
    rounds: tuple
    converged: bool
    options: RobustOptions
    tolerance: ToleranceConfig
    seconds: float

    def _summary(self):
        """Title and (label, value) rows of :class:`RobustResult`."""
        last = self.rounds[-1] if self.rounds else {}
        state = "converged" if self.converged else "not converged"
        rows = [
            ("margin reached", fmt(last.get("margin_mm"), unit="mm")),
            ("margin required", fmt(last.get("required_mm"), unit="mm")),
            ("window yield", fmt(last.get("window_yield"))),
            ("objective", fmt(last.get("objective_deg"), unit="°")),
            ("coverage", fmt(self.options.coverage)),
            ("built units sampled", str(self.tolerance.run.samples)),
        ]
        for row in self.rounds[:-1][-8:]:
            rows.append(
                (
                    f"round {row.get('round')}",
                    f"margin {fmt(row.get('margin_mm'), unit='mm')}, "
                    f"required {fmt(row.get('required_mm'), unit='mm')}",
                )
            )
        title = (
            f"RobustResult: {state} after {len(self.rounds)} rounds, {fmt(self.seconds, unit='s')}"
        )
        return title, rows

    @property
    def design(self):
        """The robust design, with ``predicted`` filled in."""
        return self.result.design

    def to_dict(self):
        """JSON-ready record of the loop (``predicted["robust"]`` of the design)."""
        run = self.tolerance.run
        return {
            "coverage": self.options.coverage,
            "max_rounds": self.options.max_rounds,
            "converged": self.converged,
            "seconds": self.seconds,
            "margin_mm": self.rounds[-1]["margin_mm"],
            "required_mm": self.rounds[-1]["required_mm"],
            "rounds": list(self.rounds),
            "samples": run.samples,
            "seed": run.seed,
            "metrics_step_deg": self.tolerance.settings.metrics_step_deg,
            "tolerances": self.tolerance.tolerances.to_dict(),
        }


def tolerance_study(design, tolerance, factory, *, calibrate=None, coverage=COVERAGE):
    """The Monte Carlo study of one design under a tolerance configuration.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    tolerance : ToleranceConfig
        Tolerances, settings, targets, and from ``run`` the samples, seed and batch size
        (its sensitivity sizes are not used).
    factory : callable
        Executor factory (:mod:`reflector_opt.util._pools`).
    calibrate : bool, optional
        Overrides ``tolerance.settings.calibrate``; False judges the distance window alone.
    coverage : float
        Coverage of the required margin.

    Returns
    -------
    reflector_opt.tolerance.ToleranceStudy
    """
    settings = tolerance.settings
    targets = tolerance.targets
    if calibrate is not None:
        settings = dataclasses.replace(settings, calibrate=calibrate)
    if not settings.calibrate:
        targets = dataclasses.replace(targets, window=True)
    return run_study(
        design,
        tolerance.tolerances,
        samples=tolerance.run.samples,
        seed=tolerance.run.seed,
        settings=settings,
        targets=targets,
        coverage=coverage,
        factory=factory,
        batch_size=tolerance.run.batch_size,
    )


def _round_record(number, limit_mm, result, study):
    """One round of :func:`robust_optimise`: the optimum and what its study found."""
    summary = study.summary
    if "required_margin_mm" not in summary:
        raise InputError(
            "robust design: no sampled unit of the optimised design can be built "
            "(a sensor inside the sphere); the tolerances are too large"
        )
    return {
        "round": number,
        "limit_mm": limit_mm,
        "margin_mm": float(np.min(result.metrics.distance_margin_mm)),
        "required_mm": summary["required_margin_mm"]["value"],
        "required_estimate_mm": summary["required_margin_mm"]["estimate"],
        "required_confidence": summary["required_margin_mm"]["confidence"],
        "window_yield": summary["yield"]["window"],
        "window_yield_interval": summary["yield_interval"]["window"],
        "objective_deg": result.objective,
        "variables": dict(result.evaluation.values),
    }


def robust_optimise(
    problem=None,
    tolerance=None,
    *,
    options=None,
    seed=0,
    budget=None,
    factory=None,
    progress=None,
):
    """Optimise with a distance margin that covers the tolerances.

    Parameters
    ----------
    problem : reflector_opt.optimiser.Problem, optional
        Its ``distance_margin_mm`` is the margin of the first round and the least of every
        round.
    tolerance : ToleranceConfig, optional
        The tolerance model and the Monte Carlo run (``run.samples`` units, ``run.seed``);
        default :class:`ToleranceConfig()`.
    options : RobustOptions, optional
        Coverage and most rounds.
    seed : int
        Seed of every search.
    budget : reflector_opt.optimiser.SearchBudget, optional
    factory : callable, optional
        Executor factory of the studies; default ``run.workers`` local processes. One
        executor serves every round (:func:`~reflector_opt.util._pools.reused`).
    progress : callable, optional
        ``progress(fraction, message)``.

    Returns
    -------
    RobustResult
        Raises :class:`~reflector_opt.util._errors.InputError` if no design meets the required
        margin, or no sampled unit can be built. A loop that reaches ``max_rounds`` without
        covering returns with ``converged`` False.
    """
    problem = Problem() if problem is None else problem
    tolerance = ToleranceConfig() if tolerance is None else tolerance
    options = RobustOptions() if options is None else options
    factory = local_processes(tolerance.run.workers) if factory is None else factory
    rounds, result, limit, converged = [], None, problem.distance_margin_mm, False
    start = time.perf_counter()
    with reused(factory) as shared:
        for k in range(options.max_rounds):
            n, label = options.max_rounds, f"robust round {k + 1}, margin {limit:.3f} mm"
            report = scaled(progress, k / n, (k + 1) / n)
            result = _round_design(problem, limit, result, k, seed, budget, report, label, options)
            report(1.0, f"{label}: tolerance study")
            study = tolerance_study(
                result.design, tolerance, shared, calibrate=False, coverage=options.coverage
            )
            rounds.append(_round_record(k + 1, limit, result, study))
            required = rounds[-1]["required_mm"]
            if rounds[-1]["margin_mm"] >= required - CONVERGENCE_MM:
                converged = True
                break
            limit = max(limit, required)
    seconds = time.perf_counter() - start
    robust = RobustResult(result, tuple(rounds), converged, options, tolerance, seconds)
    return _recorded(robust)


def _round_design(problem, limit, previous, k, seed, budget, progress, label, options):
    """Round ``k``'s optimisation at the distance margin ``limit`` (mm), from the previous
    round's design, with the search's seed, budget, progress and label. A later round that
    finds no design names the margin and the coverage (``options.coverage``) it was for."""
    (found,) = optimise_variants(
        [(label, limit)],
        lambda margin: dataclasses.replace(problem, distance_margin_mm=margin),
        initial=None if previous is None else previous.evaluation.values,
        seed=seed,
        budget=budget,
        progress=progress,
    )
    if found.error is not None and k > 0:
        raise InputError(
            f"robust design: no design keeps the distance margin {limit:.3f} mm that "
            f"covers {100 * options.coverage:g} % of units ({found.error})"
        ) from None
    if found.error is not None:
        raise found.error
    return found.result


def _recorded(robust):
    """``robust`` with its record in its design's ``predicted["robust"]``."""
    result = robust.result
    design = result.design.replace(
        predicted=result.design.predicted.replace(robust=robust.to_dict())
    )
    return dataclasses.replace(robust, result=dataclasses.replace(result, design=design))


def front_yield(front, problem, tolerance=None, *, factory=None, progress=None):
    """The yield of every feasible point of a Pareto front.

    Parameters
    ----------
    front : reflector_opt.optimiser._pareto.ParetoFront
    problem : reflector_opt.optimiser.Problem
        The problem the front was traced for (it builds each point's design).
    tolerance : ToleranceConfig, optional
        The tolerance model, settings, targets and Monte Carlo run (``run.samples`` units
        per point, ``run.seed``); with ``settings.calibrate`` false the yield counts the
        distance window alone.
    factory : callable, optional
        Executor factory; default ``run.workers`` local processes. One executor serves
        every point.
    progress : callable, optional
        ``progress(fraction, message)``.

    Returns
    -------
    reflector_opt.optimiser._pareto.ParetoFront
        A copy whose feasible points carry ``yield_fraction``, its 95 % Wilson interval
        ``yield_low``–``yield_high`` and ``yield_samples``, and whose ``yield_basis``
        records the targets, tolerances and run.
    """
    tolerance = ToleranceConfig() if tolerance is None else tolerance
    factory = local_processes(tolerance.run.workers) if factory is None else factory
    feasible = [i for i, p in enumerate(front.points) if p.feasible]
    points = list(front.points)
    with reused(factory) as shared:
        for done, i in enumerate(feasible):
            point = points[i]
            if progress is not None:
                progress(
                    done / len(feasible),
                    f"yield at margin {point.required_margin_mm:g} mm",
                )
            study = tolerance_study(problem.design(point.values), tolerance, shared)
            low, high = study.summary["yield_interval"]["all"]
            points[i] = dataclasses.replace(
                point,
                yield_fraction=study.summary["yield"]["all"],
                yield_low=low,
                yield_high=high,
                yield_samples=study.summary["samples"],
            )
    basis = {
        "targets": tolerance.targets.to_dict(),
        "calibrated": tolerance.settings.calibrate,
        "samples": tolerance.run.samples,
        "seed": tolerance.run.seed,
        "confidence": CONFIDENCE,
        "interval": "wilson",
        "tolerances": tolerance.tolerances.to_dict(),
    }
    return dataclasses.replace(front, points=tuple(points), yield_basis=basis)
