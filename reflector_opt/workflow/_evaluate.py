"""A design evaluated over its workspace, as ``reflector-opt evaluate`` does it."""

from __future__ import annotations

from reflector_opt.workflow._runs import EvaluateRun


def evaluate(design=None, *, predict=True, seed=0, progress=None, conditions=None):
    """A design's error in use, its distance and voltage ranges and its predicted calibration
    and segment errors: ``reflector-opt evaluate`` (computed in memory; nothing is written).

    Parameters
    ----------
    design : reflector_opt.design._design.Design, str, pathlib.Path or None
        The design, or its ``design.json``; the built-in default design if None.
    predict : bool, optional
        Simulate the calibration and segment errors of built units (the slow part).
    seed : int, optional
        Seed of the simulated calibration.
    progress : callable, optional
        ``progress(fraction, message)`` as the work advances.
    conditions : reflector_opt.design._conditions.Conditions, str or pathlib.Path, optional
        Operating conditions, or their TOML file; the default ones (docs/conditions.md) where
        None. The summary opens with the figures in use (``in_use``:
        :func:`~reflector_opt.report._conditions.in_use_block`) and gives the error budget in
        them.

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
    judged = search_conditions("in-use", as_conditions(conditions))
    plan_layout(design)  # the parts export would build: a design they cannot make is refused
    summary = evaluation_summary(
        design, predict=predict, seed=seed, progress=progress, conditions=judged
    )
    return EvaluateRun(design, {"in_use": in_use_block(design, conditions), **summary})
