"""``reflector-opt correct AS_BUILT.json [more …] [--design D] -o DIR``: correct the next print.

Parses the options, calls :func:`reflector_opt.workflow.correct` (pool the batch, shrink
the batch mean into a correction, choose its step by the next batch's expected loss, keep
the predicted print printable, predict), writes the run into DIR and prints it. Nothing is
written if any step fails (docs/print-loop.md).
"""

from __future__ import annotations

from reflector_opt.cli._arguments import DEFAULT_OUT, add_output_folder
from reflector_opt.cli._command import call_into_folder, print_run
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._correct import CorrectOptions


def register(subparsers):
    """Add the ``correct`` subcommand."""
    p = subparsers.add_parser(
        "correct",
        help="pre-compensate the next print by the systematic deviation of a printed batch",
        description=(
            "Pool the AS_BUILT.json files of one print batch (written by identify), estimate "
            "the deviation that repeats from print to print and the unit-to-unit scatter, "
            "correct the drawing by every systematic deviation the data determine and show "
            "to be significant, predict the next batch with and without the correction, and "
            "write DIR/design.json and the corrected parts (the checks of export)."
        ),
    )
    p.add_argument("as_built", nargs="+", metavar="AS_BUILT.json", help="identified units")
    add_output_folder(p, f"{DEFAULT_OUT}/corrected", "design.json and the corrected parts")
    add_options(p, CorrectOptions)
    p.add_argument("--json", action="store_true", help="print the full summary as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Correct, write and print; returns the exit code."""
    from reflector_opt.workflow import correct

    options = options_of(args, CorrectOptions)
    run = call_into_folder(args, correct, args.as_built, options)
    return print_run(args, run, folder=args.out)
