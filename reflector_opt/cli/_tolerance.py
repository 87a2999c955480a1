"""``reflector-opt tolerance DESIGN.json [--samples N] [--seed N] [--scheduler ADDRESS]
[-o DIR] [--tolerances FILE.toml] [--json] [--quiet]``."""

from __future__ import annotations

from reflector_opt.cli._arguments import DEFAULT_OUT, add_output_folder, deprecated_alias
from reflector_opt.cli._command import call_into_folder, print_run
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._tolerance import ToleranceOptions


def register(subparsers):
    """Add the ``tolerance`` subcommand."""
    p = subparsers.add_parser(
        "tolerance",
        help="Monte Carlo tolerance analysis of a design: yield and sensitivity",
        description=(
            "Simulate building, calibrating and validating many units of a design with random "
            "manufacturing and read-out errors; report the distance window, resolution and "
            "calibrated error distributions, the yield against targets and which tolerance "
            "drives the error. Runs on local processes or a Dask cluster (--scheduler)."
        ),
    )
    p.add_argument("design", metavar="DESIGN.json")
    add_output_folder(p, f"{DEFAULT_OUT}/tolerance", "the study's tables and figures")
    add_options(p, ToleranceOptions)
    deprecated_alias(p, "--config", "--tolerances")
    p.add_argument(
        "--json",
        action="store_true",
        help="print the summary (study.json's content and the files written) as JSON",
    )
    p.set_defaults(handler=run)


def run(args):
    """Run the study, write the outputs and print a summary; returns the exit code."""
    from reflector_opt.workflow._tolerance import tolerance

    run = call_into_folder(args, tolerance, args.design, options_of(args, ToleranceOptions))
    return print_run(args, run, folder=args.out)
