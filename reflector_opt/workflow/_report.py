"""A design's report and printable parts, as ``reflector-opt report`` writes them."""

from reflector_opt.util._declared import ConditionsFile, Options, Seed, option, takes
from reflector_opt.workflow._runs import ReportRun

#: The command recorded in an output folder's manifest when the library wrote it: a later
#: ``reflector-opt report`` into the same folder replaces its files, as it would its own.
LIBRARY_COMMAND = ("reflector_opt", "report")


class ReportOptions(Options):
    """The options of ``reflector-opt report``, declared once."""

    conditions: ConditionsFile = None
    as_built: option(
        object,
        "units printed from this design, as `reflector-opt identify` found them (AS_BUILT.json "
        "or an AsBuiltFile): adds each unit's print beside the design, its resolution and what "
        "each deviation costs",
        metavar="AS_BUILT.json",
    ) = None
    seed: option(Seed, "seed of the simulations") = 0
    cad: option(
        bool,
        "write the printable parts (STL, 3MF, previews) and run their printability and "
        "collision checks, the slowest step",
    ) = True


@takes(ReportOptions)
def report(design, options, progress=None):
    """A design's report and its printable parts, its inputs read and checked:
    ``reflector-opt report``; :meth:`~reflector_opt.workflow._runs.ReportRun.write` renders
    and writes it.

    The design must be one whose parts can be laid out (as for ``evaluate``).

    Parameters
    ----------
    design : reflector_opt.design._design.Design, str or pathlib.Path
        The design, or its ``design.json``.
    options : ReportOptions
        As keyword arguments (below); the report opens with the figures in use in the
        conditions and gives the error budget in them.
    progress : callable, optional
        ``progress(fraction, message)`` as the work advances.

    Returns
    -------
    ReportRun

    Raises
    ------
    InputError
        A design that cannot be read or whose parts cannot be laid out, an as-built file that
        cannot be read or belongs to another design.
    """
    conditions = options.conditions
    design, as_built = _checked_inputs(design, options.as_built, conditions)
    return ReportRun(design, options.seed, as_built, conditions, options.cad, progress)


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
