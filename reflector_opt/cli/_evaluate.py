"""``reflector-opt evaluate [DESIGN.json] [--json] [--no-predict] [--seed N]``.

Distance and voltage ranges of a design and its predicted calibration and segment errors. A
design whose printable parts cannot be laid out is refused with the message ``export`` gives.

Parses the options and calls :func:`reflector_opt.workflow.evaluate`; prints its summary.
"""

from __future__ import annotations

from reflector_opt.cli._output import print_json, progress_for
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._evaluate import EvaluateOptions


def register(subparsers):
    """Add the ``evaluate`` subcommand."""
    p = subparsers.add_parser(
        "evaluate",
        help="distance and voltage ranges of a design over its workspace",
        description="Evaluate a design over its workspace; with no file, the built-in default.",
    )
    p.add_argument("design", metavar="DESIGN.json", nargs="?", help="default: the built-in design")
    add_options(p, EvaluateOptions)
    p.add_argument("--json", action="store_true", help="print machine-readable JSON")
    p.set_defaults(handler=run)


def run(args):
    """Evaluate through :func:`~reflector_opt.workflow.evaluate` and print; returns the
    exit code."""
    from reflector_opt.workflow import evaluate

    with progress_for(args) as progress:
        result = evaluate(args.design, options_of(args, EvaluateOptions), progress=progress)
    if args.json:
        print_json(result.to_dict())
    else:
        print(result.text())
    return 0
