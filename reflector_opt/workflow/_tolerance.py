"""A Monte Carlo tolerance study of a design, as ``reflector-opt tolerance`` runs it.

Many units of the design are built with random manufacturing and read-out errors, calibrated
and validated (:func:`reflector_opt.tolerance._study.run_study`); their tables and the figures
(yield, errors, sensitivity) are written into one output folder, swapped in whole. The
tolerance file with the run's overrides (:func:`tolerance_config`) and the pool the units are
simulated on (:func:`~reflector_opt.util._pools.executor_factory`) are shared with
:func:`~reflector_opt.workflow._sweep.sweep_run`.
"""

from dataclasses import dataclass, replace
from pathlib import Path

from reflector_opt.util._declared import Options, Seed, option, takes
from reflector_opt.util._display import Printed
from reflector_opt.util._limits import MAX_SIMULATED_UNITS


def tolerance_config(tolerances=None, *, samples=None, seed=None):
    """The tolerance file's configuration with a run's overrides.

    Parameters
    ----------
    tolerances : str or pathlib.Path, optional
        The tolerance file (TOML, docs/tolerance.md); the built-in tolerances if None.
    samples : int, optional
        Monte Carlo samples, instead of the file's (default 500).
    seed : int, optional
        Seed of every draw, instead of the file's (default 0).

    Returns
    -------
    reflector_opt.tolerance._config.ToleranceConfig
    """
    from reflector_opt.tolerance._config import ToleranceConfig, load_tolerance_config

    config = ToleranceConfig() if tolerances is None else load_tolerance_config(tolerances)
    overrides = {k: v for k, v in (("samples", samples), ("seed", seed)) if v is not None}
    if overrides:
        config = replace(config, run=replace(config.run, **overrides))
    return config


def study_setup(tolerances, scheduler, progress, **overrides):
    """What a run of tolerance studies (``tolerance``, ``sweep``) starts from besides the
    design, each input checked before any work.

    Parameters
    ----------
    tolerances : str or pathlib.Path or None
        The tolerance file (:func:`tolerance_config`).
    scheduler : str or None
        A Dask scheduler's address; local processes (the file's ``workers``) if None.
    progress : callable or None
        ``progress(fraction, message)`` of the study.
    **overrides
        ``samples`` and ``seed`` instead of the file's (:func:`tolerance_config`).

    Returns
    -------
    (ToleranceConfig, dict)
        The configuration and the keywords every study takes from it: ``seed``,
        ``settings``, ``targets``, ``factory``, ``batch_size``, ``progress``.
    """
    from reflector_opt.util._pools import executor_factory

    config = tolerance_config(tolerances, **overrides)
    factory = executor_factory(scheduler, config.run.workers)
    study = {"seed": config.run.seed, "settings": config.settings, "targets": config.targets}
    study |= {"factory": factory, "batch_size": config.run.batch_size, "progress": progress}
    return config, study


@dataclass(frozen=True, repr=False)
class ToleranceRun(Printed):
    """A tolerance study run by :func:`tolerance`, in memory; :meth:`write` writes its
    tables and figures.

    Attributes
    ----------
    study : reflector_opt.tolerance.ToleranceStudy
        The study: its units, summary, sensitivity.
    tolerances : str or pathlib.Path or None
        The tolerance file the tolerances came from, as given (None: the built-in ones).
    out : pathlib.Path or None
        The output folder, once written.
    files : tuple of pathlib.Path
        Every file written: the study's tables, then the figures (the folder's
        ``manifest.json`` besides; empty before :meth:`write`).
    """

    study: object
    tolerances: object
    out: Path | None = None
    files: tuple = ()

    def write(self, folder, *, command=("reflector_opt", "tolerance")):
        """Write the study's tables and figures into ``folder``, whole or not at all.

        Returns
        -------
        ToleranceRun
            This run, written: ``out`` and ``files`` filled in.
        """
        from reflector_opt.workflow._runs import written

        return written(self, folder, command, lambda work: (_write(work, self.study), {}))

    def to_dict(self):
        """JSON-ready (``tolerance --json``): ``study.json``'s content, the folder, the files."""
        files = [str(f) for f in self.files]
        folder = None if self.out is None else str(self.out)
        return {**self.study.to_dict(), "folder": folder, "files": files}

    def text(self):
        """The summary the command prints: yield, distributions, margin, Sobol indices."""
        from reflector_opt.workflow._tolerance_text import format_summary

        return format_summary(self.study, self.tolerances)


class StudyOptions(Options):
    """The options every tolerance study takes (``tolerance``, ``sweep``), declared once."""

    tolerances: option(
        object,
        "tolerances and study settings (a ToleranceConfig or its TOML file, "
        "docs/tolerance.md); the built-in ones if left out",
        metavar="FILE.toml",
    ) = None
    seed: option(Seed, "seed of every draw; the tolerance file's (or 0) if left out") | None = None
    scheduler: option(
        str | None,
        "run on a Dask distributed scheduler, e.g. tcp://host:8786; local processes (the "
        "tolerance file's [run] workers) if left out",
        metavar="ADDRESS",
    ) = None


class ToleranceOptions(StudyOptions):
    """The options of ``reflector-opt tolerance``, declared once."""

    samples: (
        option(
            int,
            "Monte Carlo samples; the tolerance file's (or 500) if left out",
            metavar="N",
            ge=1,
            le=MAX_SIMULATED_UNITS,
        )
        | None
    ) = None


@takes(ToleranceOptions)
def tolerance(design, options, progress=None):
    """Run a tolerance study in memory: ``reflector-opt tolerance``;
    :meth:`ToleranceRun.write` writes its tables and figures.

    Parameters
    ----------
    design : reflector_opt.design._design.Design, str or pathlib.Path
        The design or its ``design.json``.
    options : ToleranceOptions
        As keyword arguments (below).
    progress : callable, optional
        ``progress(fraction, message)`` as the units are simulated.

    Returns
    -------
    ToleranceRun

    Raises
    ------
    InputError
        A design or tolerance file that cannot be read, or a scheduler that cannot be
        reached.
    """
    from reflector_opt.design import as_design
    from reflector_opt.tolerance._study import run_study

    design, tolerances = as_design(design), options.tolerances
    config, options = study_setup(
        tolerances, options.scheduler, progress, samples=options.samples, seed=options.seed
    )
    r = config.run
    study = run_study(
        design,
        config.tolerances,
        samples=r.samples,
        oat_samples=r.oat_samples,
        sobol_samples=r.sobol_samples,
        **options,
    )
    return ToleranceRun(study, tolerances)


def _write(work, study):
    """The study's tables and its figures (yield; errors if calibrated; sensitivity if
    measured) in ``work``; the names written."""
    from reflector_opt.report._plots import (
        error_histograms,
        save_figure,
        sensitivity_bars,
        yield_bars,
    )
    from reflector_opt.tolerance._output import write_study

    figures = {"yield.png": yield_bars}
    if study.settings.calibrate:
        figures["errors.png"] = error_histograms
    if study.one_at_a_time or study.sobol:
        figures["sensitivity.png"] = sensitivity_bars
    names = [Path(path).name for path in write_study(work, study)]
    for name, figure in figures.items():
        save_figure(figure(study), work / name)
    return [*names, *figures]
