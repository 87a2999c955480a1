"""A sweep over design variables, as ``reflector-opt sweep`` runs it.

Numbers of the design are varied over a grid (``PATH=START:STOP:N`` or ``PATH=V1,V2,…``;
:func:`reflector_opt.tolerance.sweep.parse_variable`), and each point's nominal calibrated
error, window and resolution and, with units per point, its yield are measured
(:func:`reflector_opt.tolerance.sweep.sweep`); ``sweep.csv`` (and ``sweep.png`` for one
variable) are written into one output folder, swapped in whole.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from reflector_opt.util.display import Printed

__all__ = ["SweepRun", "sweep_run"]


@dataclass(frozen=True, repr=False)
class SweepRun(Printed):
    """A sweep run and written by :func:`sweep_run`.

    Attributes
    ----------
    rows : list of dict
        One per point: the variables' values, ``status``, the nominal figures and, when
        units were drawn, ``yield`` (``sweep.csv``'s rows).
    paths : list of str
        The variables varied, e.g. ``reflector.radius_mm``.
    basis : str
        What each yield counts (:func:`~reflector_opt.workflow.tolerance_text.yield_basis`).
    out : pathlib.Path
        The output folder.
    files : tuple of pathlib.Path
        Every file written (the folder's ``manifest.json`` besides).
    """

    rows: list
    paths: list
    basis: str
    out: Path
    files: tuple

    def to_dict(self):
        """JSON-ready (``sweep --json``): the points, the folder, the files' names."""
        names = [f.name for f in self.files]
        return {"points": self.rows, "folder": str(self.out), "files": names}

    def text(self):
        """One line per point: in-use worst case, resolution, window, RMS error and yield."""
        from reflector_opt.workflow.tolerance_text import format_table

        return format_table(self.rows, self.paths, self.basis)


def sweep_run(
    design,
    vary,
    out,
    *,
    samples=0,
    tolerances=None,
    seed=None,
    scheduler=None,
    progress=None,
    command=None,
    conditions=None,
):
    """Sweep design variables over a grid and write the table: ``reflector-opt sweep``.

    Parameters
    ----------
    design : reflector_opt.design.design.Design, str or pathlib.Path
        The design or its ``design.json``.
    vary : sequence of str
        The variables, each ``PATH=START:STOP:N`` or ``PATH=V1,V2,…`` (PATH like
        ``reflector.radius_mm`` or ``sensors[0].position_mm[0]``, in the path's unit).
    out : str or pathlib.Path
        The output folder (built beside the old one and swapped in whole).
    samples : int, optional
        Units drawn per point for its yield; 0 for the nominal figures only.
    tolerances : str or pathlib.Path, optional
        The tolerance file (tolerances, targets and study settings); the built-in ones if
        None.
    seed : int, optional
        Seed of every draw (default the file's, or 0).
    scheduler : str, optional
        A Dask scheduler's address to run on; local processes (the file's ``workers``) if
        None.
    progress : callable, optional
        ``progress(fraction, message)`` as the points are measured.
    command : sequence of str, optional
        The command line recorded in the folder's manifest (default the library's).
    conditions : reflector_opt.design.conditions.Conditions, str or pathlib.Path, optional
        The operating conditions, or their TOML file, each point's in-use worst case is
        judged in (docs/conditions.md); the default conditions if None.

    Returns
    -------
    SweepRun

    Raises
    ------
    InputError
        A design, variable, conditions or tolerance file that cannot be read, a scheduler
        that cannot be reached, an output folder that cannot be one; nothing is written.
    """
    from reflector_opt.design import as_design
    from reflector_opt.design.conditions import as_conditions
    from reflector_opt.tolerance.output import write_records
    from reflector_opt.tolerance.sweep import parse_variable, sweep
    from reflector_opt.util.atomic import atomic_folder
    from reflector_opt.workflow.tolerance import study_setup
    from reflector_opt.workflow.tolerance_text import yield_basis

    design = as_design(design)
    conditions = as_conditions(conditions)
    variables = [parse_variable(spec) for spec in vary]
    config, out, options = study_setup(out, tolerances, scheduler, progress, seed=seed)
    options["conditions"] = conditions
    rows = sweep(design, variables, config.tolerances, samples=samples, **options)
    names = ["sweep.csv"]
    with atomic_folder(out, command or ("reflector_opt", "sweep")) as work:
        write_records(work / "sweep.csv", rows)
        if len(variables) == 1:
            from reflector_opt.report.plots import save_figure, sweep_figure

            save_figure(sweep_figure(rows, variables[0][0]), work / "sweep.png")
            names.append("sweep.png")
    basis = yield_basis(samples, config.run.seed, tolerances)
    paths = [path for path, _ in variables]
    return SweepRun(rows, paths, basis, out, tuple(out / name for name in names))
