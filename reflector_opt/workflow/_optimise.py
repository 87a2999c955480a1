"""One optimisation run, as ``reflector-opt optimise`` makes it: the search (one, several
starts, several sensor parts, or robust rounds against a tolerance model; in operating
conditions if given), the Pareto front, the drift front, the predicted calibration errors,
the report and the printable parts, written into one output folder."""

import contextlib
from dataclasses import dataclass, field, replace
from os import PathLike
from pathlib import Path

from reflector_opt.util._declared import takes
from reflector_opt.util._display import Printed
from reflector_opt.util._errors import InputError, NoDesignError
from reflector_opt.util._fileio import write_json
from reflector_opt.util._pools import executor_factory, reused
from reflector_opt.util._progress import Phases
from reflector_opt.workflow._optimise_text import format_run, ranking_lines
from reflector_opt.workflow._options import OptimiseOptions, prepare
from reflector_opt.workflow._runs import cad_names, cad_summary, written

#: The command recorded in an output folder's manifest when the library wrote it: a later
#: ``reflector-opt optimise`` into the same folder replaces its files, as it would its own.
LIBRARY_COMMAND = ("reflector_opt", "optimise")


#: Work of one optimisation (search, polish, verification), of one part's prediction of
#: its calibration error, of one tolerance study, of one built unit's predicted calibration
#: and of the report with its parts, s: measured on the defaults with two workers.
_WORK = {"optimisation": 11.0, "part": 3.0, "study": 10.0, "unit": 3.0, "report": 9.5}


@dataclass(frozen=True, repr=False)
class OptimiseRun(Printed):
    """An optimisation run (:func:`reflector_opt.workflow._optimise.optimise`), computed in
    memory; :meth:`write` writes it.

    Its ``repr`` and notebook display are the text ``optimise`` prints (:meth:`text`).

    Attributes
    ----------
    result : reflector_opt.optimiser.OptimisationResult
        The optimised design (``result.design``, its ``predicted`` filled in) and the search.
    robust : reflector_opt.optimiser._robust.RobustResult or None
        The robust rounds, when run against tolerances.
    front : reflector_opt.optimiser._pareto.ParetoFront or None
        The Pareto front, when traced.
    predicted : reflector_opt.tolerance._prediction.Prediction or None
        :func:`~reflector_opt.tolerance._prediction.predicted_performance` of the design, once
        written with the report.
    cad : reflector_opt.report._outputs.CadOutcome or None
        The printable parts' outcome, once written with the report.
    out : pathlib.Path or None
        The output folder, once written.
    files : tuple of pathlib.Path
        Every file written, ``design.json`` first (the folder's ``manifest.json`` besides);
        empty before :meth:`write`.
    tolerances : str or pathlib.Path or None
        Where the tolerances of the robust rounds and the yields came from, named in their
        labels: the tolerance file as given, ``"given as an object"``, or None (the built-in
        ones, or none used).
    seed : int
        The run's seed (of the report's simulations too).
    report : bool
        :meth:`write` writes the report and the printable parts.
    conditions : reflector_opt.design._conditions.Conditions or None
        The conditions the design was judged in (read-out applied), for the report's budget.
    phases : reflector_opt.util._progress.Phases or None
        The run's progress, which :meth:`write` goes on with.
    """

    result: object
    robust: object
    front: object
    predicted: object = None
    cad: object = None
    out: Path | None = None
    files: tuple = ()
    tolerances: object = None
    seed: int = 0
    report: bool = True
    conditions: object = None
    phases: object = field(default=None, compare=False)

    def write(self, folder, *, command=LIBRARY_COMMAND):
        """Write ``design.json``, the fronts, the report and the parts into ``folder``.

        The folder is written whole or not at all
        (:func:`reflector_opt.util._atomic.atomic_folder`); the same run gives the same files
        as the command with the same options.

        Parameters
        ----------
        folder : str or pathlib.Path
            The output folder: ``design.json``; with a Pareto front, ``pareto.json`` and
            ``pareto.png``; with a drift front, ``drift_front.json``; with the report, the
            report, its figures and the printable parts.
        command : sequence of str, optional
            The command line recorded in the folder's manifest, program first and
            subcommand second.

        Returns
        -------
        OptimiseRun
            This run, written: ``predicted``, ``cad``, ``out`` and ``files`` filled in.

        Raises
        ------
        InputError
            An output folder that cannot be written; nothing is written.
        """
        phases = self.phases or Phases(None, {"prediction": 1.0, "report": 1.0})
        run = written(self, folder, command, lambda work: _write(work, self, phases))
        phases.finish("written")
        return run

    @property
    def design(self):
        """The optimised :class:`~reflector_opt.design._design.Design`."""
        return self.result.design

    def ranking_lines(self):
        """The sensor parts' ranking as printed lines (none when one part was optimised).

        Returns
        -------
        list of str
        """
        choice = self.design.predicted.sensor_choice
        return ranking_lines(choice) if choice else []

    def to_dict(self):
        """JSON-ready summary (``optimise --json``): the design as ``design.json`` holds it,
        the predicted performance, the robust rounds, the Pareto front, the parts, the files."""
        return {
            "out": None if self.out is None else str(self.out),
            "seed": self.result.seed,
            "evaluations": sum(self.result.evaluations.values()),
            "design": self.design.to_dict(),
            "predicted": None if self.predicted is None else self.predicted.to_dict(),
            "robust": None if self.robust is None else self.robust.to_dict(),
            "pareto": None if self.front is None else self.front.to_dict(),
            "cad": cad_summary(self.cad, self.out),
            "files": [str(path) for path in self.files],
        }

    def text(self):
        """The text ``optimise`` prints before the files it wrote
        (:func:`~reflector_opt.workflow._optimise_text.format_run`)."""
        return format_run(self)


def run_work(prepared, options):
    """The work of each phase of :func:`optimise`, s (roughly; for the progress shares).

    Parameters
    ----------
    prepared : reflector_opt.workflow._options.Prepared
        The run's prepared settings.
    options : OptimiseOptions

    Returns
    -------
    dict
        Phase name → work: ``search``, ``pareto``, ``yield``, ``drift front``,
        ``prediction``, ``report`` (0 for a phase that does not run).
    """
    config, one = prepared.config, _WORK["optimisation"]
    workers = max(1, config.budget.workers)
    search = one
    if len(prepared.parts) > 1:
        search = len(prepared.parts) * (one + _WORK["part"]) / min(workers, len(prepared.parts))
    elif options.starts > 1:
        search = options.starts * one / workers
    if prepared.tolerance is not None:
        search = 2 * (search + _WORK["study"])  # rounds: typically two
    margins = len(config.pareto_margins_mm) * options.pareto
    units = config.problem.mechanics.n_units
    return {
        "search": search,
        "pareto": margins * one,
        "yield": margins * _WORK["study"] * (prepared.tolerance is not None),
        "drift front": (len(config.drift_fractions) + 1) * one * options.drift_front,
        "prediction": units * _WORK["unit"] * options.report,
        "report": _WORK["report"] * options.report,
    }


def _search(prepared, options, factory, progress):
    """The optimisation result and, for a robust run, its rounds (else None).

    In use with the read-out chosen (``read_out`` "chosen"): the geometry is searched in the
    read-out chosen for the default design (:func:`~reflector_opt.optimiser._readout.
    choose_read_out`; for several parts, the stated one), or, where no design passes the
    verification there, in the stated one
    (the search does not see the printed parts' walls, which a switched drive's optimum can
    cut: recorded as ``searched_in`` with the reason); then the read-out is chosen again for
    the design found. For the white-noise objective, the design is judged in the conditions
    afterwards.
    """
    from reflector_opt.optimiser._readout import choose_read_out, judged_in, with_read_out

    problem, stated = prepared.config.problem, prepared.conditions
    if problem.conditions is None:  # the white-noise objective, judged in the conditions
        result, robust = _searched(problem, prepared, options, factory, progress)
        return judged_in(result, replace(problem, conditions=stated), in_use=False), robust
    if options.read_out == "stated":
        return _searched(problem, prepared, options, factory, progress)
    searched, missed, first = problem, None, None
    try:  # several parts are searched as stated: one part's read-out is not another's
        if len(prepared.parts) < 2:
            first, _ = choose_read_out(problem.baseline_design(), stated)
            searched = replace(problem, conditions=first.conditions)
    except InputError:  # the default geometry is no design here: search as stated
        pass
    try:
        result, robust = _searched(searched, prepared, options, factory, progress)
    except NoDesignError as exc:
        if searched is problem:
            raise
        searched, missed = problem, str(exc)
        result, robust = _searched(problem, prepared, options, factory, progress)
    return with_read_out(result, searched, stated, missed, first), robust


def _searched(problem, prepared, options, factory, progress):
    """The search of :func:`_search` under ``problem``."""
    from reflector_opt.optimiser._search import optimise

    config, seed, parts = prepared.config, prepared.seed, prepared.parts
    searches = None
    if options.starts > 1 or options.scheduler is not None:
        searches = executor_factory(options.scheduler, config.budget.workers)
    if len(parts) > 1:
        from reflector_opt.optimiser._sensor_choice import choose_sensor

        chosen = choose_sensor(
            problem,
            parts,
            seed=seed,
            budget=config.budget,
            executor=searches,
            progress=progress,
        )
        return chosen.result, None
    robust = None
    if prepared.tolerance is None:
        result = optimise(
            problem,
            seed=seed,
            budget=config.budget,
            progress=progress,
            starts=options.starts,
            executor=searches,
        )
    else:
        from reflector_opt.optimiser._robust import robust_optimise

        robust = robust_optimise(
            problem,
            prepared.tolerance,
            options=config.robust,
            seed=seed,
            budget=config.budget,
            factory=factory,
            progress=progress,
        )
        result = robust.result
    if len(parts) == 1:
        from reflector_opt.optimiser._sensor_choice import record_part

        result = record_part(result, parts[0], problem, seed)
    return result, robust


@contextlib.contextmanager
def _answered(options, progress):
    """A :class:`~reflector_opt.util._errors.NoDesignError` raised inside, raised again with
    the smallest change of the settings that gives a design
    (:func:`reflector_opt.workflow._remedy.smallest_change`)."""
    from reflector_opt.workflow._remedy import smallest_change

    try:
        yield
    except NoDesignError as exc:
        raise NoDesignError(f"{exc}; {smallest_change(options, progress)}") from None


def _front(prepared, factory, progress, yield_progress):
    """The Pareto front, with each point's yield in a robust run."""
    from reflector_opt.optimiser._pareto import pareto_front
    from reflector_opt.optimiser._robust import front_yield

    config = prepared.config
    front = pareto_front(
        config.problem,
        config.pareto_margins_mm,
        seed=prepared.seed,
        budget=config.budget,
        progress=progress,
    )
    if prepared.tolerance is None:
        return front
    return front_yield(
        front, config.problem, prepared.tolerance, factory=factory, progress=yield_progress
    )


def _drift_front(prepared, result, progress):
    """``result`` with the drift front in its design's ``predicted["drift_front"]`` (the
    design optimised in the conditions, if any, recorded as the front's reference)."""
    import dataclasses

    from reflector_opt.optimiser._drift_front import drift_front

    config = prepared.config
    reference = result if config.problem.conditions is not None else None
    front = drift_front(
        config.problem,
        config.drift_fractions,
        seed=prepared.seed,
        budget=config.budget,
        progress=progress,
        reference=reference,
    )
    predicted = result.design.predicted.replace(drift_front=front.to_dict())
    design = result.design.replace(predicted=predicted)
    return dataclasses.replace(result, design=design)


def _write(work, run, phases):
    """Write an :class:`OptimiseRun`'s files into ``work``; their names and the run's ``cad``
    and ``predicted`` (``phases``: the run's :class:`~reflector_opt.util._progress.Phases`)."""
    result, front, seed = run.result, run.front, run.seed
    names, cad, predicted = ["design.json"], None, None
    result.design.save(work / "design.json")
    if result.design.predicted.drift_front:
        write_json(work / "drift_front.json", result.design.predicted.drift_front)
        names.append("drift_front.json")
    if front is not None:
        from reflector_opt.report.figures._base import save_figure
        from reflector_opt.report.figures._optimiser import pareto_figure

        write_json(work / "pareto.json", front.to_dict())
        save_figure(pareto_figure(front), work / "pareto.png")
        names += ["pareto.json", "pareto.png"]
    if run.report:
        from reflector_opt.report._outputs import write_design_outputs
        from reflector_opt.tolerance._prediction import predicted_performance

        predicted = predicted_performance(result.design, seed=seed, progress=phases("prediction"))
        report_files, cad = write_design_outputs(
            result.design,
            work,
            seed=seed,
            progress=phases("report"),
            predicted=predicted,
            conditions=run.conditions,
        )
        names += [path.name for path in report_files]
        names += cad_names(cad and cad.report)
    return names, {"cad": cad, "predicted": predicted}


def _tolerance_source(tolerances):
    """How the run's text names where its tolerances came from: the file as given, ``given
    as an object`` for a :class:`~reflector_opt.tolerance._config.ToleranceConfig`, None for
    none (the built-in ones)."""
    if tolerances is None or isinstance(tolerances, str | PathLike):
        return tolerances
    return "given as an object"


@takes(OptimiseOptions)
def optimise(options, progress=None):
    """Optimise a design in memory: what ``reflector-opt optimise`` computes, nothing written.

    The search (one, several starts, several sensor parts, or robust rounds against a
    tolerance model), the Pareto front and the drift front, as the options ask;
    :meth:`OptimiseRun.write` then writes ``design.json``, the fronts, the report and the
    printable parts into one folder, as the command does.

    Parameters
    ----------
    options : OptimiseOptions
        What to run: given as an OptimiseOptions or as its keyword arguments (below), each
        checked once against its declaration.
    progress : callable, optional
        ``progress(fraction, message)`` of the whole run, :meth:`OptimiseRun.write`'s phases
        (prediction, report) included, each phase its share by the work it does
        (:func:`run_work`).

    Returns
    -------
    OptimiseRun

    Raises
    ------
    InputError
        Options that cannot be used (:func:`reflector_opt.workflow._options.prepare`), or a
        design the search cannot make feasible (with the smallest change that gives one).
    """

    with _answered(options, progress):
        prepared = prepare(options)
    phases = Phases(progress, run_work(prepared, options))
    tolerance = prepared.tolerance
    studies = (
        contextlib.nullcontext()
        if tolerance is None
        else reused(executor_factory(options.scheduler, tolerance.run.workers))
    )
    front = None
    with studies as factory:
        with _answered(options, progress):
            result, robust = _search(prepared, options, factory, phases("search"))
        if options.pareto:
            front = _front(prepared, factory, phases("pareto"), phases("yield"))
        if options.drift_front:
            result = _drift_front(prepared, result, phases("drift front"))
    budget = result.evaluation.budget  # the conditions judged in, read-out chosen
    return OptimiseRun(
        result,
        robust,
        front,
        tolerances=_tolerance_source(options.tolerances),
        seed=prepared.seed,
        report=options.report,
        conditions=prepared.conditions if budget is None else budget.conditions,
        phases=phases,
    )
