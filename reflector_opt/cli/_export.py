"""``reflector-opt export DESIGN.json [-o DIR]``: write the printable reflector part and body."""

from __future__ import annotations

from reflector_opt.cli._arguments import DEFAULT_OUT, add_output_folder, deprecated_alias
from reflector_opt.cli._command import call_into_folder, print_run
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._export import ExportOptions


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
    add_options(p, ExportOptions)
    p.add_argument("--json", action="store_true", help="print the full report as JSON")
    for old, new in (
        ("--output", "--out"),
        ("--tolerance", "--chord-tolerance"),
        ("--params", "--config"),
    ):
        deprecated_alias(p, old, new)
    p.set_defaults(handler=run)


def run(args):
    """Export and print a summary; returns the exit code."""
    from reflector_opt.workflow._export import export

    run = call_into_folder(
        args,
        export,
        args.design,
        options_of(args, ExportOptions),
    )
    return print_run(args, run, folder=args.out)
