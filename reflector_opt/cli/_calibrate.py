"""``reflector-opt calibrate DATA.csv [--model M] [--design D] [--fit F] -o coefficients.json``.

Fits one calibration model per unit of a measured calibration CSV, prints the k-fold
cross-validated error and writes the coefficients (nothing is written if any unit fails). A
``temperature_c`` column that spans at least 1 K makes every unit's form
temperature-compensated; its thermal parameters are printed with their standard deviations.
"""

from __future__ import annotations

from reflector_opt.cli._arguments import add_output_file, refuse_output_over_inputs
from reflector_opt.cli._command import print_run
from reflector_opt.cli._output import progress_for
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._calibrate import CalibrateOptions


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
    add_options(p, CalibrateOptions)
    add_output_file(p, "the coefficients (JSON)")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Calibrate, write and print the summary; returns the exit code."""
    from reflector_opt.workflow._calibrate import calibrate

    options = options_of(args, CalibrateOptions)
    refuse_output_over_inputs(args.output, {"data": args.data, "--design": options.design})
    with progress_for(args) as progress:
        run = calibrate(args.data, options, progress=progress).write(args.output)
    return print_run(args, run, [args.output])
