"""``reflector-opt firmware coefficients.json -o calibration.h``.

Writes the calibration as a C99 header for the microcontroller (docs/robot.md), float and fixed
point, and prints its operations per frame, its fixed-point error and its code size.
"""

from __future__ import annotations

from reflector_opt.cli._arguments import add_output_file, refuse_output_over_inputs
from reflector_opt.cli._command import print_run
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._firmware import FirmwareOptions


def register(subparsers):
    """Add the ``firmware`` subcommand."""
    p = subparsers.add_parser(
        "firmware",
        help="the calibration as a C99 header for the microcontroller",
        description=(
            "Write the coefficients of calibrate as a C99 header: per unit, pitch and roll from "
            "its voltages (and temperature, where compensated), in float and in fixed point; "
            "prints the operations per frame, the fixed-point error and the code size."
        ),
    )
    p.add_argument("coefficients", help="coefficients JSON written by calibrate")
    add_options(p, FirmwareOptions)
    add_output_file(p, "the C header")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Write the header and print the summary; returns the exit code."""
    from reflector_opt.workflow._firmware import firmware

    refuse_output_over_inputs(args.output, {"coefficients": args.coefficients})
    options = options_of(args, FirmwareOptions)
    run = firmware(args.coefficients, options).write(args.output)
    return print_run(args, run, [args.output])
