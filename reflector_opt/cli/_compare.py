"""``reflector-opt compare A.json [B.json] [--conditions COND.toml] [--no-predict] [--seed N]
[-o DIR] [--json]``.

Two designs side by side: resolution, windows, drift sensitivity, the error budget in
operating conditions, the predicted calibration, and B − A of each. Parses the options and
calls :func:`reflector_opt.workflow._compare.compare`; prints its rows.
"""

from __future__ import annotations

from reflector_opt.cli._arguments import DEFAULT_OUT, add_output_folder
from reflector_opt.cli._command import call_into_folder, print_run
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._evaluate import CompareOptions


def register(subparsers):
    """Add the ``compare`` subcommand."""
    p = subparsers.add_parser(
        "compare",
        help="two designs side by side, with the differences and figures",
        description=(
            "Evaluate two designs (B defaults to the built-in design) and show each figure "
            "of both with B − A: worst-case resolution, distance and voltage windows, drift "
            "sensitivity, the error budget in --conditions, the predicted calibration. "
            "Writes resolution_maps_a.png, resolution_maps_b.png and, where the workspaces "
            "share their grid, resolution_difference.png."
        ),
    )
    p.add_argument("a", metavar="A.json")
    p.add_argument("b", metavar="B.json", nargs="?", help="default: the built-in design")
    add_options(p, CompareOptions)
    add_output_folder(p, f"{DEFAULT_OUT}/compare", "the resolution maps and their difference")
    p.add_argument("--json", action="store_true", help="print the rows as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Compare through :func:`~reflector_opt.workflow._compare.compare` and print; returns
    the exit code."""
    from reflector_opt.workflow._compare import compare

    run = call_into_folder(
        args,
        compare,
        args.a,
        args.b,
        options_of(args, CompareOptions),
    )
    return print_run(args, run, folder=args.out)
