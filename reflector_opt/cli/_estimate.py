"""``reflector-opt estimate coefficients.json LOG.csv -o angles.csv``.

Turns a voltage log into per-unit pitch and roll and, when the log holds every calibrated
unit, the tip's orientation and position. A temperature-compensated calibration needs the
log's ``temperature_c`` column (°C).
"""

from __future__ import annotations

from reflector_opt.cli._arguments import add_output_file, refuse_output_over_inputs
from reflector_opt.cli._command import print_run
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._estimate import EstimateOptions


def register(subparsers):
    """Add the ``estimate`` subcommand."""
    p = subparsers.add_parser(
        "estimate",
        help="unit and tip angles from a voltage log",
        description=(
            "Estimate every unit's pitch and roll from a voltage log (columns unit, v1, v2 and "
            "optionally sample or time, and temperature_c, which a temperature-compensated "
            "calibration needs) with the coefficients written by calibrate, and the tip's "
            "angles and position; units are chained base first in the coefficients' order. "
            "Each angle's 1σ (the calibration's cross-validated error, --noise-v through "
            "its gradient and, with --conditions, the in-use error budget's bias) is in the "
            "last columns."
        ),
    )
    p.add_argument(
        "coefficients", help="coefficients JSON written by calibrate, or AS_BUILT.json by identify"
    )
    p.add_argument("log", help="voltage log CSV")
    add_options(p, EstimateOptions)
    add_output_file(p, "the angles (CSV)")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Estimate, write and print the summary; returns the exit code."""
    from reflector_opt.workflow._estimate import estimate

    refuse_output_over_inputs(args.output, {"coefficients": args.coefficients, "log": args.log})
    run = estimate(
        args.coefficients,
        args.log,
        options_of(args, EstimateOptions),
    ).write(args.output)
    return print_run(args, run, [args.output])
