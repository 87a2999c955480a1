"""``reflector-opt optimise [--config FILE.toml] [-o DIR] [--seed N] [--surface PRESET]
[--sensor PARTS] [--conditions COND.toml] [--objective {in-use,resolution}]
[--read-out {chosen,stated}] [--starts N] [--workers N] [--pareto]
[--drift-front] [--tolerances FILE.toml] [--scheduler ADDRESS] [--no-report] [--json] [-q]
[-v]``.

Its options are declared once, in
:class:`~reflector_opt.workflow._options.OptimiseOptions`; the command parses them, calls
:func:`reflector_opt.workflow.optimise`, which makes the run, and prints its summary.
"""

from __future__ import annotations

import sys

from reflector_opt.cli._arguments import DEFAULT_OUT, add_output_folder
from reflector_opt.cli._command import call_into_folder, print_run
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._options import OptimiseOptions


def register(subparsers):
    """Add the ``optimise`` subcommand."""
    p = subparsers.add_parser(
        "optimise",
        help="optimise the reflector and sensor placement; writes design.json",
        description=(
            "Find the reflector radius, centre offset and sensor placement, with the drive "
            "and calibration they are read with, of least worst-case error in use (the default "
            "conditions, or --conditions; --objective resolution: the white-noise resolution) "
            "that keeps every sensor inside its usable range and meets the envelope, wall and "
            "no-fold constraints. With no options it runs on the built-in defaults and writes "
            "cad_out/design.json."
        ),
    )
    add_output_folder(p, DEFAULT_OUT, "design.json, the report and the parts")
    add_options(p, OptimiseOptions)
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Optimise through :func:`~reflector_opt.workflow.optimise`, print a summary (or
    ``--json``); returns the exit code."""
    from reflector_opt.workflow import optimise

    result = call_into_folder(args, optimise, options_of(args, OptimiseOptions))
    if result.robust is not None and not result.robust.converged:
        print(
            "reflector-opt optimise: warning: the robust margin did not converge in "
            f"{len(result.robust.rounds)} rounds; design.json keeps the last round "
            "(raise [robust] max_rounds)",
            file=sys.stderr,
        )
    return print_run(args, result, folder=result.out)
