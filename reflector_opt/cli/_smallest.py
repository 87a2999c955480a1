"""``reflector-opt smallest --target-deg X [--objective {in-use,resolution}] [--sensor PARTS]
[--conditions COND.toml]
[--config FILE.toml] [--workspace-deg W | --segment-range-deg R [--link-mm L]
[--segment-choices K]] [--seed N] [--starts N] [--workers N] [--scheduler ADDRESS] [-o DIR] [--json]
[-q] [-v]``.

Parses the options and calls :func:`reflector_opt.workflow._smallest.smallest`, which
traces the size–accuracy frontier and writes the smallest unit meeting the target (with a
segment's range, the choices of units and their predicted tip errors); prints the frontier,
the segment's choices and the choice.
"""

from __future__ import annotations

from reflector_opt.cli._arguments import DEFAULT_OUT, add_output_folder
from reflector_opt.cli._command import call_into_folder
from reflector_opt.cli._output import folder_lines, print_json
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._smallest import SmallestOptions


def register(subparsers):
    """Add the ``smallest`` subcommand."""
    p = subparsers.add_parser(
        "smallest",
        help="the smallest unit for an accuracy target: the size-accuracy frontier",
        description=(
            "Optimise the unit at diameters from 22 mm down, for each sensor part and on the "
            "catalogue's bearings, to the smallest that fits (to 0.5 mm); write the frontier "
            "(frontier.csv, frontier.png) and design.json of the smallest unit whose in-use "
            "worst-case error (in --conditions, the default conditions without it) meets "
            "--target-deg, with its printable parts as export writes them."
        ),
    )
    add_options(p, SmallestOptions)
    add_output_folder(
        p, f"{DEFAULT_OUT}/smallest", "design.json, its parts, frontier.csv and frontier.png"
    )
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Trace the frontier through :func:`~reflector_opt.workflow._smallest.smallest`, print
    it (or ``--json``); returns the exit code."""
    from reflector_opt.workflow._smallest import smallest

    options = options_of(args, SmallestOptions)
    result = call_into_folder(args, smallest, options)
    if args.json:
        print_json(result.to_dict())
        return 0
    judged = "in-use worst case" if options.objective == "in-use" else "objective"
    print(f"size-accuracy frontier (target {options.target_deg:g}°, the {judged}):")
    print(f"  part          mm  {judged:>17}  white noise  bearing  binding (margin)")
    print("\n".join(_row_line(row) for row in result.rows))
    print(_limit_lines(result.limits))
    if result.segment is not None:
        print(_segment_lines(result.segment, judged))
    print(f"smallest: {result!r}")
    print(result.parts.text())
    print(folder_lines(result.out, result.files, args.started))
    return 0


def _row_line(row):
    """One frontier row as a line of the printed table."""
    head = f"  {row['part']:<12} {row['unit_diameter_mm']:>5g}  "
    if row["status"] != "feasible":
        return head + f"no design fits: {row['reason']}"
    from reflector_opt.optimiser._size import judged_deg

    margin = f"{row['binding_margin']:.3g} {row['binding_unit']}".strip()
    figures = f"{judged_deg(row):>16.4f}°  {row['white_noise_deg']:>10.4f}°"
    return head + f"{figures}  {row['bearing']:<8} {row['binding']} ({margin})"


def _limit_lines(limits):
    """The smallest size each part fits and what fails below it, as lines."""
    lines = ["smallest size a design fits, and what fails below it:"]
    for limit in limits:
        head = f"  {limit['part']:<12} "
        if limit["smallest_mm"] is None:
            lines.append(head + f"none down from {limit['fails_at_mm']:g} mm: {limit['reason']}")
        elif limit["fails_at_mm"] is None:
            lines.append(head + f"{limit['smallest_mm']:g} mm (no smaller size tried)")
        else:
            lines.append(
                head + f"{limit['smallest_mm']:g} mm; at {limit['fails_at_mm']:g} mm "
                f"{limit['binding']}: {limit['reason']}"
            )
    return "\n".join(lines)


def _segment_lines(segment, judged):
    """The segment's choices (``judged``: the name of the unit's figure) and the chosen one's
    Table I beside the paper's, as lines."""
    from reflector_opt.optimiser._size import judged_deg

    lines = [
        f"segment of ±{segment['range_deg']:g}° on {segment['link_mm']:g} mm links "
        "(tip errors of built units, recommended calibration):",
        f"  units  each     length  {judged}  orientation rms/max   position rms/max",
    ]
    for c in segment["choices"]:
        head = f"  {c['n_units']:>5}  ±{c['unit_workspace_deg']:<6.4g} "
        if c["status"] != "feasible":
            lines.append(head + f"no design fits: {c['reason']}")
            continue
        lines.append(
            head + f"{c['segment_length_mm']:>5g} mm  {judged_deg(c):>{len(judged)}.4f}°  "
            f"{c['orientation_rms_deg']:.3f}° / {c['orientation_max_deg']:.3f}°    "
            f"{c['position_rms_mm']:.3f} / {c['position_max_mm']:.3f} mm"
        )
    lines.append(f"chosen: {segment['chosen']['n_units']} units; the paper's motion (Table I):")
    for axis, entry in segment["errors"]["paper_motion"].items():
        p, paper = entry["predicted"], entry["paper"]
        lines.append(
            f"  {axis:<5} ±{entry['amplitude_deg']:g}°: predicted rms {p['rms_deg']:.3f}°, "
            f"max {p['max_deg']:.3f}°; "
            f"the paper measured rms {paper['rms_deg']:g}°, max {paper['max_deg']:g}° "
            "(4 units, ±60°)"
        )
    return "\n".join(lines)
