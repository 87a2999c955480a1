"""A design evaluated over its workspace, as ``reflector-opt evaluate`` does it."""

from __future__ import annotations

from reflector_opt.util._declared import ConditionsFile, Options, Seed, option, takes
from reflector_opt.workflow._runs import EvaluateRun

__all__ = ["EvaluateOptions", "evaluate"]


class EvaluateOptions(Options):
    """The options of ``reflector-opt evaluate`` and ``compare``, declared once."""

    conditions: ConditionsFile = None
    predict: option(
        bool, "simulate the calibration and segment errors of built units (the slow part)"
    ) = True
    seed: option(Seed, "seed of the simulated calibration") = 0


@takes(EvaluateOptions)
def evaluate(design=None, options=None, progress=None):
    """A design's error in use, its distance and voltage ranges and its predicted calibration
    and segment errors: ``reflector-opt evaluate`` (computed in memory; nothing is written).

    Parameters
    ----------
    design : reflector_opt.design._design.Design, str, pathlib.Path or None
        The design, or its ``design.json``; the built-in default design if None.
    options : EvaluateOptions
        As keyword arguments (below). The summary opens with the figures in use in the
        conditions (``in_use``: :func:`~reflector_opt.report._conditions.in_use_block`) and
        gives the error budget in them.
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
    from reflector_opt.design import as_design
    from reflector_opt.design._conditions import as_conditions
    from reflector_opt.design._layout import plan_layout
    from reflector_opt.optimiser._conditions import search_conditions
    from reflector_opt.report._conditions import in_use_block
    from reflector_opt.tolerance._prediction import evaluation_summary

    design = as_design(design)
    conditions = options.conditions
    judged = search_conditions("in-use", as_conditions(conditions))
    plan_layout(design)  # the parts export would build: a design they cannot make is refused
    summary = evaluation_summary(
        design, predict=options.predict, seed=options.seed, progress=progress, conditions=judged
    )
    return EvaluateRun(design, {"in_use": in_use_block(design, conditions), **summary})
