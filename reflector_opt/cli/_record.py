"""``reflector-opt record plan.csv DEVICE REFERENCE -o data.csv``.

Records a calibration live (docs/robot.md): steps through the plan, says which pose is next,
keeps each pose once the readings settle with the reference at it, and writes the calibration
CSV ``calibrate`` reads, atomically, at the end.
"""

from __future__ import annotations

from reflector_opt.cli._arguments import add_output_file, refuse_output_over_inputs
from reflector_opt.cli._command import print_run
from reflector_opt.cli._output import progress_for
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._record import RecordOptions


def register(subparsers):
    """Add the ``record`` subcommand."""
    p = subparsers.add_parser(
        "record",
        help="record a calibration live from the device and an angle reference",
        description=(
            "Step through a plan of plan-calibration with the device's frames and an angle "
            "reference (lines time_s,unit,pitch_deg,roll_deg: an IMU or the robot's encoders), "
            "keep each pose once the readings settle with the reference at it, and write the "
            "calibration CSV calibrate reads; links are serial:PORT, udp:HOST:PORT, - or a path."
        ),
    )
    p.add_argument("plan", help="plan.csv written by plan-calibration")
    p.add_argument("device", help="the device's link")
    p.add_argument("reference", help="the angle reference's link")
    add_options(p, RecordOptions)
    add_output_file(p, "the calibration samples (CSV)")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Record, write and print the summary; returns the exit code."""
    from reflector_opt.workflow._record import record

    refuse_output_over_inputs(args.output, {"plan": args.plan})
    options = options_of(args, RecordOptions)
    with progress_for(args) as progress:
        run = record(args.plan, args.device, args.reference, options, progress=progress)
    return print_run(args, run.write(args.output), [args.output])
