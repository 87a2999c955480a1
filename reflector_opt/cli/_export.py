"""``reflector-opt export DESIGN.json [-o DIR]``: write the printable reflector part and body."""

from __future__ import annotations

from reflector_opt.cli._arguments import DEFAULT_OUT, add_output_folder, deprecated_alias
from reflector_opt.cli._command import call_into_folder, print_run
from reflector_opt.design._parts import DEFAULT_TOLERANCE_MM
from reflector_opt.workflow._export import PART_CHOICES


def register(subparsers):
    """Add the ``export`` subcommand."""
    p = subparsers.add_parser(
        "export",
        help="write the reflector part and the unit body as checked STL and 3MF files",
        description=(
            "Build the reflector part and the body of a design, check that they are "
            "printable and clear of each other over the workspace, verify the reflecting "
            "surface against the model (Eq 3), and write binary STL, 3MF and PNG previews, "
            "an interactive 3D view (view.html, one file that needs no network) and, with "
            "--format step, STEP files of exact solids."
        ),
    )
    p.add_argument("design", metavar="DESIGN.json", help="the design to build")
    add_output_folder(p, DEFAULT_OUT, "the parts, their pictures and the CAD report")
    p.add_argument(
        "--part",
        choices=sorted(PART_CHOICES),
        default="all",
        help="what to write: reflector, body, assembly (all solids at --pose) or all",
    )
    add_chord_tolerance(p)
    p.add_argument(
        "--pose",
        type=float,
        nargs=2,
        default=(0.0, 0.0),
        metavar=("PITCH", "ROLL"),
        help="pose of the assembly view, degrees (default 0 0)",
    )
    p.add_argument("--config", metavar="FILE.toml", help="CAD parameters (see docs/cad.md)")
    p.add_argument(
        "--format",
        choices=("mesh", "step"),
        default="mesh",
        help="mesh: STL and 3MF (default); step: also STEP files of the printed parts, exact "
        "solids for CAD (needs: pip install 'reflector-opt[step]')",
    )
    p.add_argument(
        "--no-preview",
        action="store_true",
        help="skip the PNG pictures and the interactive 3D view (view.html)",
    )
    p.add_argument("--json", action="store_true", help="print the full report as JSON")
    for old, new in (
        ("--output", "--out"),
        ("--tolerance", "--chord-tolerance"),
        ("--params", "--config"),
    ):
        deprecated_alias(p, old, new)
    p.set_defaults(handler=run)


def add_chord_tolerance(parser):
    """``--chord-tolerance MM``: how far the parts' meshes may depart from their surfaces."""
    parser.add_argument(
        "--chord-tolerance",
        type=float,
        default=DEFAULT_TOLERANCE_MM,
        metavar="MM",
        help=f"chord tolerance between mesh and surface, mm (default {DEFAULT_TOLERANCE_MM})",
    )


def run(args):
    """Export and print a summary; returns the exit code."""
    from reflector_opt.workflow._export import export

    run = call_into_folder(
        args,
        export,
        args.design,
        part=args.part,
        chord_tolerance_mm=args.chord_tolerance,
        config=args.config,
        pose_deg=args.pose,
        preview=not args.no_preview,
        step=args.format == "step",
    )
    return print_run(args, run, folder=args.out)
