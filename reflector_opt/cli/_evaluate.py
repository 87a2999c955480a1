"""``reflector-opt evaluate [DESIGN.json] [--json] [--no-predict] [--seed N]``.

Distance and voltage ranges of a design and its predicted calibration and segment errors. A
design whose printable parts cannot be laid out is refused with the message ``export`` gives.

Parses the options and calls :func:`reflector_opt.workflow.evaluate`; prints its summary.
"""

from __future__ import annotations

from reflector_opt.cli._arguments import seed
from reflector_opt.cli._output import print_json, progress_for


def register(subparsers):
    """Add the ``evaluate`` subcommand."""
    p = subparsers.add_parser(
        "evaluate",
        help="distance and voltage ranges of a design over its workspace",
        description="Evaluate a design over its workspace; with no file, the built-in default.",
    )
    p.add_argument("design", metavar="DESIGN.json", nargs="?", help="default: the built-in design")
    p.add_argument(
        "--conditions",
        metavar="COND.toml",
        help="operating conditions ([conditions] TOML) to judge the design in (default: the "
        "default conditions, docs/conditions.md)",
    )
    p.add_argument("--json", action="store_true", help="print machine-readable JSON")
    p.add_argument(
        "--no-predict",
        dest="predict",
        action="store_false",
        help="skip the simulated calibration and segment errors",
    )
    p.add_argument(
        "--seed",
        type=seed,
        default=0,
        metavar="N",
        help="seed of the simulated calibration (default 0)",
    )
    p.set_defaults(handler=run)


def run(args):
    """Evaluate through :func:`~reflector_opt.workflow.evaluate` and print; returns the
    exit code."""
    from reflector_opt.workflow import evaluate

    with progress_for(args) as progress:
        result = evaluate(
            args.design,
            predict=args.predict,
            seed=args.seed,
            progress=progress,
            conditions=args.conditions,
        )
    if args.json:
        print_json(result.to_dict())
    else:
        print(result.text())
    return 0
