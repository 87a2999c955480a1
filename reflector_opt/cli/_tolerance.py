"""``reflector-opt tolerance DESIGN.json [--samples N] [--seed N] [--scheduler ADDRESS]
[-o DIR] [--tolerances FILE.toml] [--json] [--quiet]``."""

from __future__ import annotations

from reflector_opt.cli._arguments import (
    DEFAULT_OUT,
    add_output_folder,
    count,
    deprecated_alias,
    seed,
)
from reflector_opt.cli._command import call_into_folder, print_run
from reflector_opt.util._limits import MAX_SIMULATED_UNITS


def add_execution_arguments(p):
    """Options shared by ``tolerance`` and ``sweep``.

    The tolerance file is ``--tolerances``, as in ``optimise`` and ``identify``; the former
    spelling ``--config`` stays accepted, hidden, with a warning.
    """
    p.add_argument(
        "--tolerances",
        metavar="FILE.toml",
        help="tolerances and study settings (see docs/tolerance.md)",
    )
    deprecated_alias(p, "--config", "--tolerances")
    p.add_argument("--seed", type=seed, metavar="N", help="seed of every draw (config or 0)")
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on a Dask distributed scheduler, e.g. tcp://host:8786 (default: local processes)",
    )


def execution_options(args):
    """The workflow's keywords of :func:`add_execution_arguments`' options."""
    return {"tolerances": args.tolerances, "seed": args.seed, "scheduler": args.scheduler}


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
    p.add_argument(
        "--samples",
        type=count(1, MAX_SIMULATED_UNITS),
        metavar="N",
        help="Monte Carlo samples (config or 500)",
    )
    add_output_folder(p, f"{DEFAULT_OUT}/tolerance", "the study's tables and figures")
    add_execution_arguments(p)
    p.add_argument(
        "--json",
        action="store_true",
        help="print the summary (study.json's content and the files written) as JSON",
    )
    p.set_defaults(handler=run)


def run(args):
    """Run the study, write the outputs and print a summary; returns the exit code."""
    from reflector_opt.workflow._tolerance import tolerance

    run = call_into_folder(
        args, tolerance, args.design, samples=args.samples, **execution_options(args)
    )
    return print_run(args, run, folder=args.out)
