"""A design evaluated over its workspace, as ``reflector-opt evaluate`` does it."""

from reflector_opt.util._declared import ConditionsFile, Options, Seed, option, takes
from reflector_opt.workflow._runs import EvaluateRun

#: How the headline names the conditions a design records.
RECORDED = "the conditions the design records (its optimise run's, read-out included)"


class PredictOptions(Options):
    """The prediction of built units' calibration, as ``evaluate`` and ``compare`` take it."""

    predict: option(
        bool, "simulate the calibration and segment errors of built units (the slow part)"
    ) = True
    seed: option(Seed, "seed of the simulated calibration") = 0


class EvaluateOptions(PredictOptions):
    """The options of ``reflector-opt evaluate``, declared once."""

    conditions: option(
        ConditionsFile,
        "operating conditions (Conditions, or a [conditions] TOML file, docs/conditions.md) "
        "the design is judged in; those the design records (its optimise run's, read-out "
        "included) if left out, else the default conditions",
    ) = None


class CompareOptions(PredictOptions):
    """The options of ``reflector-opt compare``, declared once: both designs are judged in
    the same conditions, their calibrations simulated with the same seed."""

    conditions: ConditionsFile = None


@takes(EvaluateOptions)
def evaluate(design=None, options=None, progress=None):
    """A design's error in use, its distance and voltage ranges and its predicted calibration
    and segment errors: ``reflector-opt evaluate`` (computed in memory; nothing is written).

    Parameters
    ----------
    design : reflector_opt.design._design.Design, str, pathlib.Path or None
        The design, or its ``design.json``; the built-in default design if None.
    options : EvaluateOptions
        As keyword arguments (below). Without conditions, those the design records
        (``predicted.conditions``, as ``optimise`` wrote them with the read-out it chose;
        the headline names them :data:`RECORDED` where they differ from the defaults), else
        the default ones (docs/conditions.md). The summary opens with the figures in use
        (``in_use``: :func:`~reflector_opt.report._conditions.in_use_block`) and gives the
        error budget in them.
    progress : callable, optional
        ``progress(fraction, message)`` as the work advances.

    Returns
    -------
    EvaluateRun

    Raises
    ------
    InputError
        A design that cannot be read, or whose printable parts cannot be laid out (the
        message ``export`` gives).
    """
    import msgspec

    from reflector_opt.design import as_design
    from reflector_opt.design._conditions import as_conditions
    from reflector_opt.design._layout import plan_layout
    from reflector_opt.optimiser._conditions import search_conditions
    from reflector_opt.report._conditions import in_use_block
    from reflector_opt.tolerance._prediction import evaluation_summary

    design = as_design(design)
    conditions = options.conditions
    recorded = recorded_conditions(design) if conditions is None else None
    conditions = conditions if recorded is None else recorded  # a file keeps its name
    judged = search_conditions("in-use", as_conditions(conditions))
    plan_layout(design)  # the parts export would build: a design they cannot make is refused
    summary = evaluation_summary(
        design, predict=options.predict, seed=options.seed, progress=progress, conditions=judged
    )
    in_use = in_use_block(design, conditions)
    if recorded is not None:
        in_use = msgspec.structs.replace(in_use, conditions_source=RECORDED)
    return EvaluateRun(design, msgspec.structs.replace(summary, in_use=in_use))


def recorded_conditions(design):
    """The conditions ``design`` records (``predicted.conditions.conditions``), or None where
    it records none or the default ones.

    Raises
    ------
    InputError
        A recorded table that is no longer read, naming the key.
    """
    from reflector_opt.design._conditions import Conditions, parse_conditions
    from reflector_opt.util._errors import InputError

    if not design.predicted.conditions:
        return None
    table = design.predicted.conditions.conditions
    try:
        recorded = parse_conditions({"conditions": table})
    except InputError as error:
        raise InputError(
            f"design.json predicted.conditions: {error}; give --conditions to judge it"
        ) from None
    return None if recorded == Conditions() else recorded
