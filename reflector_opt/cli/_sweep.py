"""``reflector-opt sweep DESIGN.json --vary PATH=START:STOP:N [--vary …] [--samples N]
[--conditions COND.toml] [--seed N] [--scheduler ADDRESS] [-o DIR] [--tolerances FILE.toml]
[--quiet]``."""

from __future__ import annotations

from reflector_opt.cli._arguments import DEFAULT_OUT, add_output_folder, count
from reflector_opt.cli._command import call_into_folder, print_run
from reflector_opt.cli._tolerance import add_execution_arguments, execution_options
from reflector_opt.util._limits import MAX_SIMULATED_UNITS


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
    p.add_argument(
        "--samples",
        dest="units_per_point",
        type=count(0, MAX_SIMULATED_UNITS),
        default=0,
        metavar="N",
        help="units per point for the yield (0)",
    )
    p.add_argument(
        "--conditions",
        metavar="COND.toml",
        help="operating conditions each point's in-use worst case is judged in "
        "(docs/conditions.md; default: the default conditions)",
    )
    add_output_folder(p, f"{DEFAULT_OUT}/sweep", "sweep.csv and sweep.png")
    add_execution_arguments(p)
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
        samples=args.units_per_point,
        conditions=args.conditions,
        **execution_options(args),
    )
    return print_run(args, run, folder=args.out)
