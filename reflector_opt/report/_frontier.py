"""The size–accuracy frontier in figures and in the report (:mod:`reflector_opt.optimiser._size`).

A design written by ``reflector-opt smallest`` carries ``predicted["size_frontier"]`` (the
target, the row chosen and every frontier row) and, with a segment's range,
``predicted["segment_choice"]`` (:mod:`reflector_opt.optimiser._segment_choice`).
:func:`frontier_blocks` turns them into the report's "Size and segment" section; a design
without them gets none.
"""

from reflector_opt.optimiser._size import judged_deg, judged_in_use
from reflector_opt.report.figures._base import single_axes

#: The columns of the report's frontier table (the third names the figure judged,
#: :func:`_judged_name`).
FRONTIER_HEADER = (
    "part",
    "diameter (mm)",
    "objective (°)",
    "white-noise floor (°)",
    "bearing",
    "binding (margin)",
)
#: The columns of the report's segment table.
SEGMENT_HEADER = (
    "units",
    "each unit (±°)",
    "length (mm)",
    "objective (°)",
    "tip orientation RMS / max (°)",
    "tip position RMS / max (mm)",
)


def _frontier_row(r):
    if r["status"] != "feasible":
        return (
            r["part"],
            f"{r['unit_diameter_mm']:g}",
            "–",
            "–",
            r.get("bearing") or "–",
            f"no design fits: {r.get('binding')}",
        )
    margin = f"{r['binding_margin']:.3g} {r['binding_unit']}".strip()
    carried = r.get("carried_from_mm")
    objective = f"{judged_deg(r):.4f}"
    if carried is not None:
        objective += f" (the {carried:g} mm design)"
    floor = r.get("white_noise_deg")
    return (
        r["part"],
        f"{r['unit_diameter_mm']:g}",
        objective,
        "–" if floor is None else f"{floor:.4f}",
        r["bearing"],
        f"{r['binding']} ({margin})",
    )


def _segment_row(c):
    if c["status"] != "feasible":
        return (str(c["n_units"]), f"{c['unit_workspace_deg']:.4g}", "–", "–", "–", "–")
    return (
        str(c["n_units"]),
        f"{c['unit_workspace_deg']:.4g}",
        f"{c['segment_length_mm']:g}",
        f"{judged_deg(c):.4f}",
        f"{c['orientation_rms_deg']:.3f} / {c['orientation_max_deg']:.3f}",
        f"{c['position_rms_mm']:.3f} / {c['position_max_mm']:.3f}",
    )


def _segment_blocks(segment):
    """The segment's choices and the chosen one's motions beside the paper's Table I."""
    chosen = segment["chosen"]
    paper = segment["errors"]["paper_motion"]
    lines = "; ".join(
        f"{axis} ±{e['amplitude_deg']:g}°: RMS {e['predicted']['rms_deg']:.3f}°, max "
        f"{e['predicted']['max_deg']:.3f}° (the paper measured {e['paper']['rms_deg']:g}° and "
        f"{e['paper']['max_deg']:g}° with four units over ±60°)"
        for axis, e in paper.items()
    )
    return [
        ("h3", f"Segment of ±{segment['range_deg']:g}°"),
        (
            "p",
            f"Each unit turns its share of the range, ±R/N in pitch and roll, on links of "
            f"{segment['link_mm']:g} mm; the fewest units are those the bearing's tilt "
            "permits. Tip errors are predicted with built units (exact optics, drawn from the "
            "tolerance model), each calibrated with the recommended form, the segment swept "
            "in pitch and in roll (docs/smallest.md). Chosen: "
            f"{chosen['n_units']} units, the fewest that no other choice beats in both tip "
            f"orientation and tip position. Its sweeps: {lines}.",
        ),
        ("table", SEGMENT_HEADER, [_segment_row(c) for c in segment["choices"]]),
    ]


def frontier_blocks(design, figures):
    """Report blocks of a design's size–accuracy frontier and segment (none without them).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    figures : dict
        ``{file name: Figure}``; the frontier's figure is added as ``frontier.png``.

    Returns
    -------
    list of tuple
        Blocks as :func:`reflector_opt.report._report.report_blocks` returns them: a heading,
        the choice, the frontier as a table and a figure, and with a segment its choices.
    """
    record = design.predicted.size_frontier
    if not record:
        return []
    rows, chosen = record["frontier"], record["chosen"]
    figures["frontier.png"] = frontier_figure(rows, record["target_deg"])
    name = _judged_name(rows)
    header = (*FRONTIER_HEADER[:2], f"{name} (°)", *FRONTIER_HEADER[3:])
    blocks = [
        ("h2", "Size and segment"),
        (
            "p",
            f"The smallest unit whose {name} meets {record['target_deg']:g}°: the "
            f"{chosen['part']} on the {chosen['bearing']} at {chosen['unit_diameter_mm']:g} mm "
            f"({judged_deg(chosen):.4f}°). Each row is one single-envelope optimisation "
            "at that diameter, or the design of a smaller one when it is better (a larger "
            "envelope holds it); binding is the constraint with the least margin, or what "
            "failed where no design fits (docs/smallest.md).",
        ),
        ("table", header, [_frontier_row(r) for r in rows]),
        ("img", "frontier.png", f"Best {name} against the unit's diameter, per part"),
    ]
    segment = design.predicted.segment_choice
    return blocks + ([] if not segment else _segment_blocks(segment))


def _judged_name(rows):
    """What a frontier's target judges: the in-use worst case where its rows have one."""
    return "in-use worst case" if any(judged_in_use(r) for r in rows) else "objective"


def frontier_figure(rows, target_deg=None, ax=None):
    """Best achievable figure the target judges against the unit's diameter, one line per
    sensor part (:func:`~reflector_opt.optimiser._size.judged_deg`: the in-use worst case, the
    white-noise floor dotted beside it, where the rows have one; else the objective).

    Parameters
    ----------
    rows : sequence of dict
        Frontier rows (``part``, ``unit_diameter_mm``, ``status``, ``objective_deg``).
    target_deg : float, optional
        Drawn as a horizontal line.
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        Feasible points joined per part (degrees against mm); each part's largest size no
        design fits marked with a cross on the axis.
    """
    fig, ax = single_axes(ax, (6.4, 4.0))
    name = _judged_name(rows)
    for part in dict.fromkeys(r["part"] for r in rows):
        own = sorted((r for r in rows if r["part"] == part), key=lambda r: r["unit_diameter_mm"])
        ok = [r for r in own if r["status"] == "feasible"]
        size = [r["unit_diameter_mm"] for r in ok]
        (line,) = ax.plot(size, [judged_deg(r) for r in ok], "o-", label=part)
        if name != "objective":
            floor = [r["white_noise_deg"] for r in ok]
            ax.plot(size, floor, ":", color=line.get_color(), label=f"{part}, white noise")
        failed = [r["unit_diameter_mm"] for r in own if r["status"] != "feasible"]
        if failed and ok:
            ax.plot([max(failed)], [judged_deg(ok[0])], "x", color=line.get_color())
    if target_deg is not None:
        ax.axhline(target_deg, color="0.4", linestyle="--", label=f"target {target_deg:g}°")
    ax.set_xlabel("unit diameter (mm)")
    ax.set_ylabel(f"{name} (°)")
    ax.set_title("Size–accuracy frontier (× : largest size no design fits)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return fig
