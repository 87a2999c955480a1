"""The figures in use as every command words them: one name per figure, said the same in
``evaluate``, ``compare``, ``optimise`` and the report.

A block of figures in use is a :class:`reflector_opt.design._in_use.InUse`
(:func:`reflector_opt.report._conditions.in_use_block`'s, or ``optimise``'s
``predicted.conditions``): the worst case over the workspace of the total
error in use (per angle), its RMS and median, the white-noise floor (the worst-case 1σ
resolution) beside them, the conditions named, and the default design's in the same conditions.
The worst case is the figure to quote (:data:`QUOTE`).
"""

from pathlib import Path

from msgspec import UNSET

#: How the conditions are named where none were given: the defaults are used.
DEFAULT_CONDITIONS = "the default conditions (docs/conditions.md)"

#: Which figure to quote, said once wherever the figures in use are printed.
QUOTE = (
    "quote the worst case in use: what a calibrated unit can read in these conditions; the "
    "white-noise floor is its limit where nothing drifts"
)


def in_use_where(block):
    """Where the figures of an :class:`~reflector_opt.design._in_use.InUse` are: the
    conditions named, their temperature and read-out."""
    c = block.conditions
    named = "" if block.conditions_source is UNSET else f" in {block.conditions_source}"
    compensated = ", temperature-compensated" if c["temperature_compensated"] else ""
    return (
        f"in use{named} (±{c['temperature_range_k']:g} K, {c['drive']} drive at "
        f"{c['sample_rate_hz']:g} Sa/s{compensated}; form misfit left out)"
    )


def in_use_figures(block, floor_deg=None):
    """The worst case in use (per angle), its RMS and median, and the white-noise floor."""
    floor = floor_deg if block.white_noise_floor_deg is UNSET else block.white_noise_floor_deg
    text = (
        f"worst case {block.worst_case_deg:.4f}° (pitch {block.worst_pitch_deg:.4f}°, "
        f"roll {block.worst_roll_deg:.4f}°){_figure(', RMS', block.rms_deg)}"
        f"{_figure(', median', block.median_deg)}"
    )
    floor = "" if floor is None else f"; white-noise floor {floor:.4f}° (worst-case 1σ resolution)"
    return text + floor


def _figure(name, value_deg):
    return "" if value_deg is UNSET else f"{name} {value_deg:.4f}°"


def in_use_lines(block, floor_deg=None):
    """The headline of an :class:`~reflector_opt.design._in_use.InUse` (whose white-noise
    floor is ``floor_deg`` where it gives none): the figures, the default design's and the
    improvement, which figure to quote, the sources that bind."""
    lines = [f"  {in_use_where(block)}: {in_use_figures(block, floor_deg)}"]
    base = block.baseline
    if base is not UNSET:
        where = "as stated" if base.conditions == "as stated" else "in the same conditions"
        lines.append(
            f"  default design {where}: worst case {base.worst_case_deg:.4f}°"
            f"{_figure(', RMS', base.rms_deg)}, median {base.median_deg:.4f}°; improvement in "
            f"use {block.improvement:.2f}× (worst), {block.improvement_median:.2f}× (median)"
        )
    lines.append(f"  {QUOTE}")
    binding = block.binding
    sources = ", ".join(
        f"{name} {e:.3f}° ({100 * binding['shares'][name]:.0f} %)"
        for name, e in binding["sources_deg"].items()
    )
    pitch, roll = binding["pose_deg"]
    lines.append(f"  at its worst ({binding['angle']} at {pitch:g}°, {roll:g}°): {sources}")
    return lines


def conditions_source(conditions):
    """How the headline names the conditions: their file, the given ones, or the defaults.

    Parameters
    ----------
    conditions : reflector_opt.design._conditions.Conditions, str, pathlib.Path or None
        As given to ``evaluate``, ``compare`` or ``report`` (None: the defaults).

    Returns
    -------
    str
    """
    if conditions is None:
        return DEFAULT_CONDITIONS
    return str(conditions) if isinstance(conditions, str | Path) else "the conditions given"
