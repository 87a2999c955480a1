"""``reflector-opt report DESIGN.json [-o DIR] [--as-built AS_BUILT.json] [--no-cad] [--seed N]
[--quiet]``."""

from __future__ import annotations

from pathlib import Path

from reflector_opt.cli.arguments import DEFAULT_OUT, add_output_folder, output_folder, seed
from reflector_opt.cli.output import cad_files, folder_lines, progress_for


def register(subparsers):
    """Add the ``report`` subcommand."""
    p = subparsers.add_parser(
        "report",
        help="write a design report (Markdown with PNG figures, self-contained HTML) and the parts",
        description=(
            "Write report.md with its PNG figures and report.html, one file with its images "
            "inside: the design, its constraints and their slack (zero slack flagged), sensor "
            "windows with a section through each sensor's plane, resolution maps, the predicted "
            "calibration and segment errors beside the paper's, the printability of the parts "
            "with links to their files, and print and material notes; with --as-built, how "
            "each printed unit was built and which of its deviations cost resolution. The "
            "parts (STL, 3MF) are written too when the design passes the printability checks."
        ),
    )
    p.add_argument("design", help="design.json")
    add_output_folder(p, f"{DEFAULT_OUT}/report", "the report, its figures and the parts")
    p.add_argument(
        "--as-built",
        metavar="AS_BUILT.json",
        help="units printed from this design, as `reflector-opt identify` found them: adds "
        "each unit's print beside the design, its resolution and what each deviation costs",
    )
    p.add_argument("--seed", type=seed, default=0, metavar="N", help="seed of the simulations")
    p.add_argument(
        "--no-cad",
        action="store_true",
        help="write the report only: no printable parts (STL, 3MF, previews) and no "
        "printability or collision checks, the slowest step",
    )
    p.set_defaults(handler=run)


def run(args):
    """Write the report and print where it went; returns the exit code."""
    from reflector_opt.design import load_design
    from reflector_opt.design.layout import plan_layout
    from reflector_opt.report.asbuilt import read_as_built
    from reflector_opt.report.report import write_design_outputs
    from reflector_opt.util.atomic import atomic_folder

    output_folder(args.out)  # refused before any work, named by its option
    design = load_design(args.design)
    plan_layout(design)  # as evaluate: a design whose parts cannot be made is refused
    as_built = None if args.as_built is None else read_as_built(args.as_built, design)
    with progress_for(args) as progress, atomic_folder(args.out, args.argv) as work:
        written, cad = write_design_outputs(
            design,
            work,
            seed=args.seed,
            cad=not args.no_cad,
            progress=progress,
            as_built=as_built,
        )
    if cad is not None and cad.error is not None:
        print(cad.summary())
    out = Path(args.out)
    files = [*(out / path.name for path in written), *cad_files(cad and cad.report, out)]
    print(folder_lines(out, files, args.started))
    return 0
