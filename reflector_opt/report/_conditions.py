"""The report's section on the unit in use: drift sensitivity, and the error budget in conditions.

Every report shows the design's drift sensitivity — the angle error from a 1 % change of the
light path, common to the sensors and for each alone
(:func:`reflector_opt.analysis._budget.drift_sensitivity`) — since it is what a few kelvin of
warm-up cost, and the error budget per source
(:func:`reflector_opt.analysis._budget.error_budget`) in the operating conditions given, the
default ones (docs/conditions.md) otherwise, the drive scheme's effects, and a figure of where
in the workspace each source costs most.

The figures in use (:func:`in_use_block`) are what ``evaluate``, ``compare``, ``optimise`` and
the report give first (:mod:`reflector_opt.report._in_use` words them): the worst case, RMS and
median over the workspace of the total error in use, the white-noise floor beside them, and
the default design's in the same conditions.
"""

import numpy as np

from reflector_opt.analysis._budget import drift_sensitivity, error_budget
from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.design import default_design
from reflector_opt.design._conditions import as_conditions
from reflector_opt.design._in_use import InUse, InUseBaseline
from reflector_opt.optimiser._conditions import (
    binding_sources,
    median_total_deg,
    rms_total_deg,
    search_conditions,
    worst_totals,
)
from reflector_opt.report._in_use import conditions_source
from reflector_opt.report.figures._base import new_figure, pose_map
from reflector_opt.util._fileio import json_number

#: File name of the budget's maps in the report folder.
BUDGET_FIGURE = "error_budget_maps.png"
_HEADER = ("", "pitch RMS (°)", "roll RMS (°)", "pitch max (°)", "roll max (°)")


def joint_sentence(joint):
    """What of the joint's clearance the calibration learns and what stays, in one sentence."""
    if not joint.seated:
        return (
            f"Joint: clearance {joint.clearance_um:g} µm, free or its load reversing, "
            f"±{joint.stays_um[0]:.1f} µm on every axis that no calibration learns."
        )
    return (
        f"Joint: clearance {joint.clearance_um:g} µm seated by the tendons' preload, "
        f"{joint.learned_um:.1f} µm along the load learned by the calibration and "
        f"±{joint.stays_um[0]:.1f} µm across it left (the friction cone)."
    )


def assumed_sentence(assumed):
    """The assumed figures the budget leans on, named (each with its source)."""
    if not assumed:
        return "Every figure of this budget is published or derived."
    listed = "; ".join(f"{f['figure']} = {f['value']} ({f['source']})" for f in assumed)
    return f"This budget leans on {len(assumed)} assumed figure(s): {listed}."


def _zero(conditions):
    """The reference's zero as the sentence gives it: as stated, or its kind's class."""
    zero = list(conditions.reference_zero())
    if conditions.reference_zero_deg is not None:
        return f"{zero}°"
    figure = conditions.reference_figure()
    return f"{zero}° (the {figure['kind']} class of {figure['name']})"


def _row(name, error):
    e = error.to_dict()
    return (
        name,
        *(
            f"{e[k]:.3f}"
            for k in ("pitch_rms_deg", "roll_rms_deg", "pitch_max_deg", "roll_max_deg")
        ),
    )


def budget_maps_figure(budget):
    """Where in the workspace each source of the budget costs most.

    One map per source that costs anything: the larger of the pitch and roll error of its
    worst scenario at each pose (the noise at 1σ), degrees; a line saying so where none does.

    Parameters
    ----------
    budget : reflector_opt.analysis._budget.ErrorBudget

    Returns
    -------
    matplotlib.figure.Figure
    """
    shown = {n: m.max(axis=-1) for n, m in budget.maps.items() if np.max(m) > 1e-6}
    if not shown:
        fig = new_figure((4.3, 1.2))
        fig.text(0.5, 0.5, "No source costs anything in these conditions.", ha="center")
        return fig
    cols = min(3, len(shown))
    rows = -(-len(shown) // cols)
    fig = new_figure((4.3 * cols, 3.6 * rows))
    axes = np.atleast_1d(fig.subplots(rows, cols)).ravel()
    pitch, roll = budget.pitch_deg[:, 0], budget.roll_deg[0]
    for ax, (name, values) in zip(axes, shown.items(), strict=False):
        pose_map(fig, ax, pitch, roll, values, "angle error (°)", cmap="magma")
        ax.set_title(f"{name.replace('_', ' ')}: worst {values.max():.3f}°")
    for ax in axes[len(shown) :]:
        ax.set_visible(False)
    return fig


def _figures(budget):
    pitch, roll = worst_totals(budget)
    return {
        "worst_case_deg": budget.worst_case_deg,
        "worst_pitch_deg": pitch,
        "worst_roll_deg": roll,
        "rms_deg": rms_total_deg(budget),
        "median_deg": median_total_deg(budget),
        "binding": binding_sources(budget),
    }


def budget_in_use(design, conditions=None):
    """The design's error budget in the conditions, the default ones where None.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    conditions : reflector_opt.design._conditions.Conditions, str, pathlib.Path or None
        The conditions or their file
        (:func:`~reflector_opt.optimiser._conditions.search_conditions`).

    Returns
    -------
    reflector_opt.analysis._budget.ErrorBudget
        On the budget's 1° grid, the calibration form's misfit left out.
    """
    return error_budget(design, search_conditions("in-use", as_conditions(conditions)))


def in_use_block(design, conditions=None, budget=None):
    """The headline in use: the design's total error in the conditions beside its white-noise
    floor, and the default design's in the same conditions.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    conditions : reflector_opt.design._conditions.Conditions, str, pathlib.Path or None
        The conditions or their file; the defaults where None
        (:func:`~reflector_opt.optimiser._conditions.search_conditions`).
    budget : reflector_opt.analysis._budget.ErrorBudget, optional
        The design's budget in them, if already computed.

    Returns
    -------
    reflector_opt.design._in_use.InUse
        With ``conditions_source`` (:func:`conditions_source`), the worst case, RMS
        (:func:`~reflector_opt.optimiser._conditions.rms_total_deg`) and median, the sources
        that bind, the white-noise floor (the worst-case 1σ resolution on the workspace grid,
        None where infinite) and the default design in this design's unit
        (:func:`~reflector_opt.design._defaults.default_design`) in the same conditions, with
        ``improvement`` and ``improvement_median`` (its worst case and median over this
        design's), degrees. The calibration form's misfit is left out, as in the optimiser's
        objective.
    """
    budget = budget_in_use(design, conditions) if budget is None else budget
    floor = evaluate_metrics(design, design.workspace.step_deg).worst_resolution_deg
    base = InUseBaseline(**_figures(error_budget(default_design(like=design), budget.conditions)))
    figures = _figures(budget)
    return InUse(
        conditions=budget.conditions.to_dict(),
        conditions_source=conditions_source(conditions),
        white_noise_floor_deg=json_number(floor),
        baseline=base,
        improvement=base.worst_case_deg / figures["worst_case_deg"],
        improvement_median=base.median_deg / figures["median_deg"],
        **figures,
    )


def conditions_blocks(design, figures, budget):
    """Report blocks on the unit in use; the budget's figure added to ``figures``.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    figures : dict
        ``{file name: figure}``, extended in place.
    budget : reflector_opt.analysis._budget.ErrorBudget
        The design's budget in the conditions given, or the default ones.

    Returns
    -------
    list of tuple
        Blocks as :func:`reflector_opt.report._report.report_blocks` returns them.
    """
    drift = drift_sensitivity(design)
    figures[BUDGET_FIGURE] = budget_maps_figure(budget)
    c = budget.conditions
    rows = [_row(n, e) for n, e in budget.sources.items()] + [_row("total", budget.total)]
    return [
        ("h2", "In use"),
        (
            "p",
            "Angle error from a 1 % change of the light path (LED output, drive current or "
            "detector gain: a few kelvin of temperature), common to the sensors and for each "
            "alone, linearised through the voltage Jacobian over the workspace "
            "(docs/conditions.md).",
        ),
        ("table", ("1 % change", *_HEADER[1:]), [_row(n, e) for n, e in drift.items()]),
        (
            "p",
            f"Error budget in use: ±{c.temperature_range_k:g} K from calibration, ambient "
            f"{c.ambient_mv:g} mV and flicker {c.ambient_flicker_mv:g} mV, {c.drive} drive "
            f"({budget.drive.frame_rate_hz:g} frames/s), neighbour crosstalk "
            f"{c.neighbour_crosstalk:g}, reference zero {_zero(c)} and twist "
            f"{c.reference_twist_deg:g}°, latency {c.reference_latency_ms:g} ms at "
            f"{c.angular_speed_deg_s:g} °/s, supply ±{c.supply_change_mv:g} mV "
            f"({c.adc_reference} ADC reference), {c.hours_since_calibration:g} h of LED use. "
            f"{joint_sentence(budget.joint)} The form source is left out here (evaluate "
            "reports it). Total: RMS root-sum-square, max summed. Worst case in use "
            f"{budget.worst_case_deg:.4f}° (at the top of this report).",
        ),
        ("p", assumed_sentence(budget.assumed)),
        ("table", ("source", *_HEADER[1:]), rows),
        ("img", BUDGET_FIGURE, "Where each source costs most (worst scenario, noise 1σ)"),
    ]
