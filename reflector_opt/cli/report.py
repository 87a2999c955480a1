"""``reflector-opt report DESIGN.json [--out DIR] [--no-cad] [--seed N] [--quiet]``."""

from __future__ import annotations

from pathlib import Path

from reflector_opt.cli.arguments import seed
from reflector_opt.design import load_design
from reflector_opt.report.report import write_design_outputs
from reflector_opt.util.atomic import atomic_folder
from reflector_opt.util.progress import ProgressLine


def register(subparsers):
    """Add the ``report`` subcommand."""
    p = subparsers.add_parser(
        "report",
        help="write a design report (Markdown and HTML with PNG figures) and the printable parts",
        description=(
            "Write report.md and report.html with their figures: the design, its constraint "
            "margins, sensor windows, resolution maps, the predicted calibration and segment "
            "errors beside the paper's, and the printability of the parts. The parts (STL, "
            "3MF) are written too when the design passes the printability checks."
        ),
    )
    p.add_argument("design", help="design.json")
    p.add_argument("--out", metavar="DIR", default="report", help="output folder (report)")
    p.add_argument("--seed", type=seed, default=0, metavar="N", help="seed of the simulations")
    p.add_argument("--no-cad", action="store_true", help="skip the CAD export (about 6 s)")
    p.add_argument("--quiet", action="store_true", help="no progress line")
    p.set_defaults(handler=run)


def run(args):
    """Write the report and print where it went; returns the exit code."""
    design = load_design(args.design)
    with (
        ProgressLine(enabled=False if args.quiet else None) as progress,
        atomic_folder(args.out, args.argv) as work,
    ):
        written, cad = write_design_outputs(
            design, work, seed=args.seed, cad=not args.no_cad, progress=progress
        )
    print(format_outputs(written, cad, args.out))
    return 0


def format_outputs(written, cad, folder):
    """Lines naming the report pages (in ``folder``), the parts written or why none were."""
    folder = Path(folder)
    lines = [
        f"wrote {folder / written[0].name} and {folder / written[1].name} "
        f"({len(written) - 2} figures)"
    ]
    if cad is not None:
        lines.append(cad.summary(folder))
    return "\n".join(lines)
