"""A sweep over design variables, as ``reflector-opt sweep`` runs it.

Numbers of the design are varied over a grid (``PATH=START:STOP:N`` or ``PATH=V1,V2,…``;
:func:`reflector_opt.tolerance._sweep.parse_variable`), and each point's nominal calibrated
error, window and resolution and, with units per point, its yield are measured
(:func:`reflector_opt.tolerance._sweep.sweep`); ``sweep.csv`` (and ``sweep.png`` for one
variable) are written into one output folder, swapped in whole.
"""

from dataclasses import dataclass
from pathlib import Path

from reflector_opt.util._declared import ConditionsFile, option, takes
from reflector_opt.util._display import Printed
from reflector_opt.util._limits import MAX_SIMULATED_UNITS
from reflector_opt.workflow._tolerance import StudyOptions, study_setup


@dataclass(frozen=True, repr=False)
class SweepRun(Printed):
    """A sweep run by :func:`sweep`, in memory; :meth:`write` writes its table.

    Attributes
    ----------
    rows : list of dict
        One per point: the variables' values, ``status``, the nominal figures and, when
        units were drawn, ``yield`` (``sweep.csv``'s rows).
    paths : list of str
        The variables varied, e.g. ``reflector.radius_mm``.
    basis : str
        What each yield counts (:func:`~reflector_opt.workflow._tolerance_text.yield_basis`).
    out : pathlib.Path or None
        The output folder, once written.
    files : tuple of pathlib.Path
        Every file written (the folder's ``manifest.json`` besides; empty before
        :meth:`write`).
    """

    rows: list
    paths: list
    basis: str
    out: Path | None = None
    files: tuple = ()

    def write(self, folder, *, command=("reflector_opt", "sweep")):
        """Write ``sweep.csv`` and, for one variable, ``sweep.png`` into ``folder``, whole or
        not at all.

        Returns
        -------
        SweepRun
            This run, written: ``out`` and ``files`` filled in.
        """
        from reflector_opt.tolerance._output import write_records
        from reflector_opt.workflow._runs import written

        def write_into(work):
            write_records(work / "sweep.csv", self.rows)
            if len(self.paths) != 1:
                return ["sweep.csv"], {}
            from reflector_opt.report._plots import save_figure, sweep_figure

            save_figure(sweep_figure(self.rows, self.paths[0]), work / "sweep.png")
            return ["sweep.csv", "sweep.png"], {}

        return written(self, folder, command, write_into)

    def to_dict(self):
        """JSON-ready (``sweep --json``): the points, the folder, the files' names."""
        names = [f.name for f in self.files]
        folder = None if self.out is None else str(self.out)
        return {"points": self.rows, "folder": folder, "files": names}

    def text(self):
        """One line per point: in-use worst case, resolution, window, RMS error and yield."""
        from reflector_opt.workflow._tolerance_text import format_table

        return format_table(self.rows, self.paths, self.basis)


class SweepOptions(StudyOptions):
    """The options of ``reflector-opt sweep``, declared once."""

    samples: option(
        int,
        "units drawn per point for its yield; 0 for the nominal figures only",
        metavar="N",
        ge=0,
        le=MAX_SIMULATED_UNITS,
    ) = 0
    conditions: ConditionsFile = None


@takes(SweepOptions)
def sweep(design, vary, options, progress=None):
    """Sweep design variables over a grid, in memory: ``reflector-opt sweep``;
    :meth:`SweepRun.write` writes the table.

    Parameters
    ----------
    design : reflector_opt.design._design.Design, str or pathlib.Path
        The design or its ``design.json``.
    vary : sequence of str
        The variables, each ``PATH=START:STOP:N`` or ``PATH=V1,V2,…`` (PATH like
        ``reflector.radius_mm`` or ``sensors[0].position_mm[0]``, in the path's unit).
    options : SweepOptions
        As keyword arguments (below): each point's in-use worst case is judged in the
        conditions.
    progress : callable, optional
        ``progress(fraction, message)`` as the points are measured.

    Returns
    -------
    SweepRun

    Raises
    ------
    InputError
        A design, variable, conditions or tolerance file that cannot be read, a scheduler
        that cannot be reached.
    """
    from reflector_opt.design import as_design
    from reflector_opt.design._conditions import as_conditions
    from reflector_opt.tolerance._sweep import parse_variable
    from reflector_opt.tolerance._sweep import sweep as sweep_points
    from reflector_opt.workflow._tolerance_text import yield_basis

    design, tolerances, samples = as_design(design), options.tolerances, options.samples
    conditions = as_conditions(options.conditions)
    variables = [parse_variable(spec) for spec in vary]
    config, options = study_setup(tolerances, options.scheduler, progress, seed=options.seed)
    options["conditions"] = conditions
    rows = sweep_points(design, variables, config.tolerances, samples=samples, **options)
    basis = yield_basis(samples, config.run.seed, tolerances)
    return SweepRun(rows, [path for path, _ in variables], basis)
