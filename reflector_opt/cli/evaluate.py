"""``reflector-opt evaluate [DESIGN.json] [--json]``: distance and voltage ranges of a design."""

from __future__ import annotations

import json

from reflector_opt.design import default_design, load_design
from reflector_opt.evaluation import evaluate_design


def register(subparsers):
    """Add the ``evaluate`` subcommand."""
    p = subparsers.add_parser(
        "evaluate",
        help="distance and voltage ranges of a design over its workspace",
        description="Evaluate a design over its workspace; with no file, the built-in default.",
    )
    p.add_argument("design", nargs="?", help="design.json (default: the built-in design)")
    p.add_argument("--json", action="store_true", help="print machine-readable JSON")
    p.set_defaults(handler=run)


def run(args):
    """Evaluate and print; returns the exit code."""
    design = load_design(args.design) if args.design else default_design()
    summary = evaluate_design(design)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(format_summary(summary))
    return 0


def format_summary(summary):
    """Human-readable lines for an :func:`evaluate_design` summary."""
    lines = [f"workspace: {summary['workspace']['poses']} poses"]
    for s in summary["sensors"]:
        d, v = s["distance_mm"], s["volts"]
        status = "inside" if s["in_range"] else "OUTSIDE"
        lines.append(
            f"{s['name']} ({s['model']}): d {d['min']:.3f}–{d['max']:.3f} mm "
            f"(usable {s['range_mm'][0]}–{s['range_mm'][1]} mm: {status}), "
            f"V {v['min']:.3f}–{v['max']:.3f} V"
        )
    lines.append(
        "design stays inside the sensor range"
        if summary["in_range"]
        else "design leaves the sensor range"
    )
    return "\n".join(lines)
