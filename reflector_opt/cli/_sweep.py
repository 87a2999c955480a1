"""``reflector-opt sweep DESIGN.json --vary PATH=START:STOP:N [--vary …] [--samples N]
[--conditions COND.toml] [--seed N] [--scheduler ADDRESS] [-o DIR] [--tolerances FILE.toml]
[--quiet]``."""

from __future__ import annotations

from reflector_opt.cli._arguments import DEFAULT_OUT, add_output_folder, deprecated_alias
from reflector_opt.cli._command import call_into_folder, print_run
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._sweep import SweepOptions


def register(subparsers):
    """Add the ``sweep`` subcommand."""
    p = subparsers.add_parser(
        "sweep",
        help="nominal performance and tolerance yield over a grid of design variables",
        description=(
            "Change numbers of the design over a grid (--vary PATH=START:STOP:N or "
            "PATH=V1,V2,…; PATH like reflector.radius_mm or sensors[0].position_mm[0]) and "
            "report each point's in-use worst-case error (in --conditions, the default "
            "conditions without them), nominal calibrated error, window and white-noise "
            "resolution and, with "
            "--samples N, its yield over N simulated units. Writes sweep.csv (and sweep.png "
            "for one variable)."
        ),
    )
    p.add_argument("design", metavar="DESIGN.json")
    p.add_argument(
        "--vary", action="append", required=True, metavar="PATH=SPEC", help="a design variable"
    )
    add_output_folder(p, f"{DEFAULT_OUT}/sweep", "sweep.csv and sweep.png")
    add_options(p, SweepOptions)
    deprecated_alias(p, "--config", "--tolerances")
    p.add_argument("--json", action="store_true", help="print the points as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Run the sweep, write sweep.csv (and sweep.png) and print a table; returns the exit code."""
    from reflector_opt.workflow._sweep import sweep

    run = call_into_folder(
        args,
        sweep,
        args.design,
        args.vary,
        options_of(args, SweepOptions),
    )
    return print_run(args, run, folder=args.out)
