"""``reflector-opt correct AS_BUILT.json [more …] [--design D] -o DIR``: correct the next print.

Parses the options, calls :func:`reflector_opt.workflow.correct_run` (pool the batch, shrink
the batch mean into a correction, choose its step by the next batch's expected loss, keep
the predicted print printable, predict, write DIR) and prints what it returns. Nothing is
written if any step fails (docs/print-loop.md).
"""

from __future__ import annotations

from reflector_opt.cli._arguments import DEFAULT_OUT, add_output_folder, number, output_folder, seed
from reflector_opt.cli._command import print_run
from reflector_opt.cli._export import add_chord_tolerance
from reflector_opt.cli._output import progress_for


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
    p.add_argument(
        "--design",
        metavar="DESIGN.json",
        help="the design to correct: the one the units were printed from (default: the one "
        "the as-built files record)",
    )
    add_output_folder(p, f"{DEFAULT_OUT}/corrected", "design.json and the corrected parts")
    _add_correction_options(p)
    p.add_argument(
        "--no-prediction", action="store_true", help="skip the prediction of the next batch"
    )
    p.add_argument(
        "--seed", type=seed, default=0, metavar="N", help="seed of the predicted calibration"
    )
    p.add_argument("--config", metavar="FILE.toml", help="CAD parameters (see docs/cad.md)")
    add_chord_tolerance(p)
    p.add_argument("--no-preview", action="store_true", help="skip the PNG pictures")
    p.add_argument("--json", action="store_true", help="print the full summary as JSON")
    p.set_defaults(handler=run)


def _add_correction_options(p):
    """The options that decide which deviations are corrected."""
    p.add_argument(
        "--assume-systematic",
        action="store_true",
        help="with fewer than 3 units, take their deviation as systematic (it cannot be told "
        "from the scatter)",
    )
    p.add_argument(
        "--level",
        type=number(0, 10, low_open=True),
        default=2.0,
        metavar="T",
        help="shrink each resolved combination's correction by max(0, 1 − (T/t)²): nothing "
        "below |t| = T (default 2)",
    )
    p.add_argument(
        "--scatter-prior",
        type=number(0, 100, low_open=True),
        default=1.0,
        metavar="S",
        help="centre of the unit-to-unit scatter's prior, × the tolerance model's (default 1)",
    )
    p.add_argument(
        "--max-std",
        type=number(0, 10, low_open=True),
        default=1.0,
        metavar="S",
        help="correct a combination only where the batch mean is known to within S × the "
        "tolerance spread (default 1)",
    )
    p.add_argument(
        "--model-form",
        choices=("auto", "simulate", "none"),
        default="auto",
        help="weigh the identification's model-form bias as an uncertainty common to the "
        "batch: the term the as-built files record, or if they record none, simulated on "
        "units with physics the fast model lacks (auto, the default; about 10 s); simulate: "
        "always simulated; none: trust the identification's model",
    )


def run(args):
    """Correct, export, report; returns the exit code."""
    from reflector_opt.workflow import correct_run

    export = {"tolerance_mm": args.chord_tolerance, "params": args.config}
    with progress_for(args) as progress:
        run = correct_run(
            args.as_built,
            out=output_folder(args.out),
            progress=progress,
            command=args.argv,
            design=args.design,
            assume_systematic=args.assume_systematic,
            level=args.level,
            max_std=args.max_std,
            model_form=args.model_form,
            scatter_prior=args.scatter_prior,
            predict=not args.no_prediction,
            seed=args.seed,
            export_options={**export, "preview": not args.no_preview},
        )
    return print_run(args, run, folder=args.out)
