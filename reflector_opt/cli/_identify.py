"""``reflector-opt identify CAL.csv [--design D] [--curve U:S=FILE …] [--batch B] -o OUT.json``.

Identifies how each unit of a calibration CSV was built (reflector radius and centre, each
sensor's seat, gain and offset; the batch's surface), with each parameter's uncertainty and
whether the data determine it, and the angle reference's zero offsets and twist in each
unit's calibration (prior: the stated defaults, ``--conditions`` or none with
``--reference-zero fixed``); prints the determined deviations and the reference's parameters
and writes ``AS_BUILT.json`` (nothing is written if any unit fails).
"""

from __future__ import annotations

from reflector_opt.cli._arguments import add_output_file, refuse_output_over_inputs
from reflector_opt.cli._command import print_run
from reflector_opt.cli._output import progress_for
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._identify import IdentifyOptions


def register(subparsers):
    """Add the ``identify`` subcommand."""
    p = subparsers.add_parser(
        "identify",
        help="identify how printed units were built from their calibration data",
        description=(
            "Estimate each unit's as-built geometry and read-out (and the batch's surface) "
            "from a calibration CSV (columns unit, v1, v2, pitch_deg, roll_deg), with the "
            "tolerance model as the prior, and write AS_BUILT.json."
        ),
    )
    p.add_argument("data", help="calibration CSV (one or more units)")
    add_options(p, IdentifyOptions)
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    add_output_file(p, "AS_BUILT.json")
    p.set_defaults(handler=run)


def run(args):
    """Identify, write and print the summary; returns the exit code."""
    from reflector_opt.workflow._identify import identify

    options = options_of(args, IdentifyOptions)
    inputs = {"data": args.data, "--design": options.design, "--tolerances": options.tolerances}
    inputs["--conditions"] = options.conditions
    inputs.update({f"--curve {c}": c.partition("=")[2] or None for c in options.curves})
    refuse_output_over_inputs(args.output, inputs)
    with progress_for(args) as progress:
        run = identify(args.data, options, progress=progress).write(args.output)
    return print_run(args, run, [args.output])
