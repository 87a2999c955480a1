"""The report's section on the unit in use: drift sensitivity, and the error budget in conditions.

Every report shows the design's drift sensitivity — the angle error from a 1 % change of the
light path, common to the sensors and for each alone
(:func:`reflector_opt.analysis.budget.drift_sensitivity`) — since it is what a few kelvin of
warm-up cost. Given operating conditions (docs/conditions.md), it adds the error budget per
source (:func:`reflector_opt.analysis.budget.error_budget`), the drive scheme's effects, and a
figure of where in the workspace each source costs most.
"""

from __future__ import annotations

import numpy as np

from reflector_opt.analysis.budget import drift_sensitivity, error_budget
from reflector_opt.report.figures.base import new_figure, pose_map

__all__ = ["BUDGET_FIGURE", "budget_maps_figure", "conditions_blocks"]

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
    worst scenario at each pose (the noise at 1σ), degrees.

    Parameters
    ----------
    budget : reflector_opt.analysis.budget.ErrorBudget

    Returns
    -------
    matplotlib.figure.Figure
    """
    shown = {n: m.max(axis=-1) for n, m in budget.maps.items() if np.max(m) > 1e-6}
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


def conditions_blocks(design, figures, conditions=None):
    """Report blocks on the unit in use; the budget's figure added to ``figures``.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    figures : dict
        ``{file name: figure}``, extended in place.
    conditions : reflector_opt.design.conditions.Conditions, optional

    Returns
    -------
    list of tuple
        Blocks as :func:`reflector_opt.report.report.report_blocks` returns them.
    """
    drift = drift_sensitivity(design)
    blocks = [
        ("h2", "In use"),
        (
            "p",
            "Angle error from a 1 % change of the light path (LED output, drive current or "
            "detector gain: a few kelvin of temperature), common to the sensors and for each "
            "alone, linearised through the voltage Jacobian over the workspace "
            "(docs/conditions.md).",
        ),
        ("table", ("1 % change", *_HEADER[1:]), [_row(n, e) for n, e in drift.items()]),
    ]
    if conditions is None:
        blocks.append(("p", "No operating conditions given: no error budget."))
        return blocks
    budget = error_budget(design, conditions)
    figures[BUDGET_FIGURE] = budget_maps_figure(budget)
    c = conditions
    rows = [_row(n, e) for n, e in budget.sources.items()] + [_row("total", budget.total)]
    return [
        *blocks,
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
            "reports it). Total: RMS root-sum-square, max summed. Worst-case total error "
            f"{budget.worst_case_deg:.3f}°.",
        ),
        ("p", assumed_sentence(budget.assumed)),
        ("table", ("source", *_HEADER[1:]), rows),
        ("img", BUDGET_FIGURE, "Where each source costs most (worst scenario, noise 1σ)"),
    ]
