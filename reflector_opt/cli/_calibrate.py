"""``reflector-opt calibrate DATA.csv [--model M] [--design D] [--fit F] -o coefficients.json``.

Fits one calibration model per unit of a measured calibration CSV, prints the k-fold
cross-validated error and writes the coefficients (nothing is written if any unit fails). A
``temperature_c`` column that spans at least 1 K makes every unit's form
temperature-compensated; its thermal parameters are printed with their standard deviations.
"""

from __future__ import annotations

from reflector_opt.calibration._choices import FITS
from reflector_opt.cli._arguments import (
    add_accept_units,
    add_output_file,
    count,
    refuse_output_over_inputs,
    seed,
)
from reflector_opt.cli._command import print_run
from reflector_opt.cli._output import progress_for
from reflector_opt.workflow._calibrate import DEFAULT_FOLDS


def register(subparsers):
    """Add the ``calibrate`` subcommand."""
    p = subparsers.add_parser(
        "calibrate",
        help="fit per-unit calibrations to measured data (CSV)",
        description=(
            "Fit one calibration model per unit to a CSV with columns unit, v1, v2, "
            "pitch_deg, roll_deg (one row per sample) and write the coefficients as JSON. With "
            "a temperature_c column (°C) spanning at least 1 K, each unit's form is "
            "temperature-compensated (its sensors' gain and offset change per kelvin fitted "
            "with it); the logs to estimate then need that column too."
        ),
    )
    p.add_argument("data", help="calibration CSV")
    p.add_argument(
        "--model",
        default="eq6",
        help="eq5, eq6 (the paper's, default), polyN (e.g. poly4), auto (chosen per unit by "
        "cross-validation) or physical (the design's model fitted per unit; needs --design)",
    )
    p.add_argument(
        "--design",
        metavar="DESIGN.json",
        help="the units' design (needed by --model physical; its sensors' supply is the "
        "temperature compensation's pivot, default 3.3 V)",
    )
    p.add_argument("--fit", default="lsq", help=f"{', '.join(FITS)} (default lsq)")
    p.add_argument(
        "--folds",
        type=count(0, 1000),
        default=DEFAULT_FOLDS,
        help=f"cross-validation folds; 0 skips (default {DEFAULT_FOLDS})",
    )
    p.add_argument(
        "--seed", type=seed, default=0, metavar="N", help="seed of the fold shuffle (default 0)"
    )
    p.add_argument(
        "--temperature-degree",
        type=int,
        choices=(1, 2),
        default=1,
        metavar="{1,2}",
        help="the temperature compensation's gain in ΔT: 1 linear (default), 2 with each "
        "sensor's curvature too (data at three temperatures at least, as docs/conditions.md "
        "recommends for a dome-shaped light path)",
    )
    add_output_file(p, "the coefficients (JSON)")
    add_accept_units(p, "the calibration CSV")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Calibrate, write and print the summary; returns the exit code."""
    from reflector_opt.workflow._calibrate import calibrate

    refuse_output_over_inputs(args.output, {"data": args.data, "--design": args.design})
    with progress_for(args) as progress:
        run = calibrate(
            args.data,
            model=args.model,
            fit=args.fit,
            folds=args.folds,
            seed=args.seed,
            design=args.design,
            progress=progress,
            accept_units=args.accept_units,
            temperature_degree=args.temperature_degree,
        ).write(args.output)
    return print_run(args, run, [args.output])
