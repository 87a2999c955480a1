"""One driver for the studies: variants of a problem, each optimised.

The Pareto front (a distance margin per variant, :mod:`~reflector_opt.optimiser._pareto`), the
drift front (a drift limit, :mod:`~reflector_opt.optimiser._drift_front`), the size frontier (a
diameter, :mod:`~reflector_opt.optimiser._size`), the sensor choice (a catalogue part,
:mod:`~reflector_opt.optimiser._sensor_choice`) and robust design (a round's margin,
:mod:`~reflector_opt.optimiser._robust`) each optimise variants of one base problem.
:func:`optimise_variants` runs a set of them and gives back one :class:`Variant` each: what
varied, the optimisation or the error that stopped it, and the study's figures of it.

Variants run here in turn, each warm-started from what the ones before found (``initial`` a
function of them), or as independent tasks of an executor (:func:`in_tasks`, the one executor
path of the studies, over :func:`reflector_opt.util._pools.run_batches`): each search is
seeded, so the results are the same wherever they run.
"""

import dataclasses
import functools
import time
from dataclasses import dataclass, field

from reflector_opt.optimiser._search import SearchBudget, optimise
from reflector_opt.util._errors import InputError
from reflector_opt.util._pools import local_processes, run_batches
from reflector_opt.util._progress import scaled


@dataclass(frozen=True)
class Variant:
    """One variant of a study's problem, optimised.

    Attributes
    ----------
    label : str
        How the study names it (its progress messages' prefix).
    value : object
        What varies: a margin (mm), a drift limit (degrees per 1 %), a diameter (mm), a part.
    problem : reflector_opt.optimiser._problem.Problem or None
        The variant's problem; None when its settings are refused.
    result : reflector_opt.optimiser._result.OptimisationResult or None
        The optimisation; None when no design was found.
    error : reflector_opt.util._errors.InputError or None
        Why not: settings no design can meet, or a search that found no verified design.
    figures : dict
        What the study's ``figures(result, problem)`` computed of the result (empty without).
    seconds : float
        Wall time of the optimisation and its figures, s.
    """

    label: str
    value: object
    problem: object = None
    result: object = None
    error: Exception | None = None
    figures: dict = field(default_factory=dict)
    seconds: float = 0.0

    @property
    def reason(self):
        """The error's one line, or None."""
        return None if self.error is None else str(self.error)

    @property
    def values(self):
        """The design variables found, or None."""
        return None if self.result is None else dict(self.result.evaluation.values)


def in_tasks(fn, items, budget, executor=None, progress=None):
    """``fn(item, budget)`` for each item, each a task of an executor.

    Parameters
    ----------
    fn : callable
        Picklable (a module-level function, or a :func:`functools.partial` of one).
    items : sequence
        Picklable.
    budget : reflector_opt.optimiser._search.SearchBudget
        Handed to each task with one worker: each task is one process, BLAS on one thread.
    executor : callable, optional
        Executor factory (:mod:`reflector_opt.util._pools`), e.g. a Dask cluster's; default
        ``budget.workers`` local processes.
    progress : callable, optional
        ``progress(fraction, message)`` as the tasks finish.

    Returns
    -------
    list
        ``fn``'s results in the order of ``items``.
    """
    factory = local_processes(budget.workers) if executor is None else executor
    args = (fn, dataclasses.replace(budget, workers=1))
    batches = run_batches(_task, args, [[item] for item in items], factory, progress=progress)
    return [out for batch in batches for out in batch]


def _task(args, batch):
    """Worker side of :func:`in_tasks`."""
    from threadpoolctl import threadpool_limits

    fn, budget = args
    with threadpool_limits(limits=1):
        return [fn(item, budget) for item in batch]


def optimise_variants(
    variants, vary, *, initial=None, figures=None, budget=None, progress=None, **search
):
    """Optimise the variant ``vary(value)`` of a problem for each value.

    Parameters
    ----------
    variants : sequence of (str, object)
        Each variant's label and value.
    vary : callable
        ``vary(value)`` -> :class:`~reflector_opt.optimiser._problem.Problem`, called here; an
        :class:`~reflector_opt.util._errors.InputError` it raises is the variant's error.
    initial : dict or callable, optional
        The design placed in every search's initial population, or ``initial(done)`` of
        the variants done before: then the variants run here, in order.
    figures : callable, optional
        ``figures(result, problem)`` -> dict, computed where the variant runs (picklable when
        the variants are tasks).
    budget : reflector_opt.optimiser._search.SearchBudget, optional
        Of every search.
    progress : callable, optional
        ``progress(fraction, message)``.
    **search
        ``seed``, ``starts`` and ``executor`` of every search
        (:func:`~reflector_opt.optimiser._search.optimise`). Several variants not chained by
        ``initial`` run each as one task of the executor (:func:`in_tasks`; default
        ``budget.workers`` local processes); one alone runs here with the budget's workers,
        the executor serving its starts.

    Returns
    -------
    tuple of Variant
        In the order of ``variants``.
    """
    budget = SearchBudget() if budget is None else budget
    varied = [_varied(vary, label, value) for label, value in variants]
    todo = [v for v in varied if v.error is None]
    if len(todo) > 1 and not callable(initial):
        executor = search.pop("executor", None)
        run = functools.partial(_optimised, figures=figures, initial=initial, **search)
        found = iter(in_tasks(run, todo, budget, executor, progress))
        return tuple(v if v.error is not None else next(found) for v in varied)
    done = []
    for i, variant in enumerate(varied):
        if variant.error is None:
            start = initial(done) if callable(initial) else initial
            part = scaled(progress, i / len(varied), (i + 1) / len(varied))
            report = _prefixed(part, variant.label)
            variant = _optimised(variant, budget, figures, progress=report, initial=start, **search)
        done.append(variant)
    return tuple(done)


def _varied(vary, label, value):
    """The variant of ``value`` before its search: its problem, or the error refusing it."""
    try:
        return Variant(label, value, vary(value))
    except InputError as exc:
        return Variant(label, value, error=exc)


def _prefixed(progress, label):
    return lambda fraction, message: progress(fraction, f"{label}: {message}")


def _optimised(variant, budget, figures, **search):
    """``variant`` with its optimisation and figures, or the error its search raised."""
    t0 = time.perf_counter()
    try:
        result = optimise(variant.problem, budget=budget, **search)
    except InputError as exc:
        return dataclasses.replace(variant, error=exc, seconds=time.perf_counter() - t0)
    extra = {} if figures is None else figures(result, variant.problem)
    seconds = time.perf_counter() - t0
    return dataclasses.replace(variant, result=result, figures=extra, seconds=seconds)
