"""``reflector-opt stream LINK coefficients.json -o angles.csv [--mcap FILE]``.

Reads a device's frames (docs/robot.md) and writes each frame's per-unit pitch and roll with
their 1σ and the tip's pose, block by block, until the link ends, a bound is reached or Ctrl-C
(which prints the summary and exits 130, every file closed whole).
"""

from __future__ import annotations

from reflector_opt.cli._arguments import add_output_file, refuse_output_over_inputs
from reflector_opt.cli._command import print_run
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._stream import StreamOptions


def register(subparsers):
    """Add the ``stream`` subcommand."""
    p = subparsers.add_parser(
        "stream",
        help="live angles from a device's frames",
        description=(
            "Read a device's frames (docs/robot.md) from a link and write each frame's per-unit "
            "pitch and roll with their 1σ and the tip's pose to a CSV, flushed block by block, "
            "and with --mcap to an MCAP log with ROS 2 schemas (JointState, TFMessage); "
            "prints the frames, the link's faults and whether the estimator kept up."
        ),
    )
    p.add_argument("link", help="serial:PORT, udp:HOST:PORT, - (standard input) or a file")
    p.add_argument("coefficients", help="coefficients JSON written by calibrate")
    add_options(p, StreamOptions)
    add_output_file(p, "the angles (CSV)")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Stream, write and print the summary; returns the exit code (130 when interrupted)."""
    from reflector_opt.workflow._stream import stream

    options = options_of(args, StreamOptions)
    inputs = {"coefficients": args.coefficients, "link": args.link}
    refuse_output_over_inputs(args.output, inputs)
    if options.mcap:
        refuse_output_over_inputs(options.mcap, {**inputs, "--out": args.output}, "--mcap")
    run = stream(args.link, args.coefficients, options).write(args.output)
    code = print_run(args, run)
    return 130 if run.interrupted else code
