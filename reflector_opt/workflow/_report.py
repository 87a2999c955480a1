"""A design's report and printable parts, as ``reflector-opt report`` writes them."""

from __future__ import annotations

from reflector_opt.workflow._runs import ReportRun

#: The command recorded in an output folder's manifest when the library wrote it: a later
#: ``reflector-opt report`` into the same folder replaces its files, as it would its own.
LIBRARY_COMMAND = ("reflector_opt", "report")


def report(design, *, as_built=None, seed=0, cad=True, progress=None, conditions=None):
    """A design's report and its printable parts, its inputs read and checked:
    ``reflector-opt report``; :meth:`~reflector_opt.workflow._runs.ReportRun.write` renders
    and writes it.

    The design must be one whose parts can be laid out (as for ``evaluate``).

    Parameters
    ----------
    design : reflector_opt.design._design.Design, str or pathlib.Path
        The design, or its ``design.json``.
    as_built : str, pathlib.Path or reflector_opt.asbuilt._asbuiltfile.AsBuiltFile, optional
        ``AS_BUILT.json`` of units printed from the design: adds the as-built section.
    seed : int, optional
        Seed of the simulations.
    cad : bool, optional
        Write the printable parts (STL, 3MF, previews) and run their checks, the slowest step.
    progress : callable, optional
        ``progress(fraction, message)`` as the work advances.
    conditions : reflector_opt.design._conditions.Conditions, str or pathlib.Path, optional
        Operating conditions, or their TOML file; the default ones (docs/conditions.md) where
        None: the report opens with the figures in use and gives the error budget in them.

    Returns
    -------
    ReportRun

    Raises
    ------
    InputError
        A design that cannot be read or whose parts cannot be laid out, an as-built file that
        cannot be read or belongs to another design.
    """
    design, as_built = _checked_inputs(design, as_built, conditions)
    return ReportRun(design, seed, as_built, conditions, cad, progress)


def _checked_inputs(design, as_built, conditions):
    """The design (its parts laid out) and its as-built file, read, and the conditions checked,
    before any output is written."""
    from reflector_opt.design import Design, load_design
    from reflector_opt.design._conditions import as_conditions
    from reflector_opt.design._layout import plan_layout
    from reflector_opt.report._asbuilt import read_as_built

    if not isinstance(design, Design):
        design = load_design(design)
    plan_layout(design)  # as evaluate: a design whose parts cannot be made is refused
    if as_built is not None:
        as_built = read_as_built(as_built, design)
    as_conditions(conditions)  # the report names them by their file: read there again
    return design, as_built
