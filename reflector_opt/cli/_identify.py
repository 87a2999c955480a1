"""``reflector-opt identify CAL.csv [--design D] [--curve U:S=FILE …] [--batch B] -o OUT.json``.

Identifies how each unit of a calibration CSV was built (reflector radius and centre, each
sensor's seat, gain and offset; the batch's surface), with each parameter's uncertainty and
whether the data determine it, and the angle reference's zero offsets and twist in each
unit's calibration (prior: the stated defaults, ``--conditions`` or none with
``--reference-zero fixed``); prints the determined deviations and the reference's parameters
and writes ``AS_BUILT.json`` (nothing is written if any unit fails).
"""

from __future__ import annotations

from reflector_opt.cli._arguments import (
    add_accept_units,
    add_output_file,
    number,
    refuse_output_over_inputs,
)
from reflector_opt.cli._command import print_run
from reflector_opt.cli._output import progress_for


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
    p.add_argument(
        "--design", metavar="DESIGN.json", help="the units' design (default: the built-in design)"
    )
    p.add_argument(
        "--curve",
        action="append",
        default=[],
        metavar="[UNIT:]SENSOR=FILE",
        help="a sensor's flat-target curve measured before assembly (the fit-sensor CSV); "
        "repeat for each sensor and unit, e.g. --curve 1:S1=s1.csv",
    )
    p.add_argument(
        "--tolerances",
        metavar="FILE.toml",
        help="tolerance config whose [tolerances] are the prior (default: the built-in ones)",
    )
    p.add_argument(
        "--reference-sigma",
        type=number(0, 5, "degrees"),
        default=None,
        metavar="DEG",
        help="RMS noise of the angle reference at each pose (default 0.05°)",
    )
    _add_reference_options(p)
    p.add_argument(
        "--no-profiles", action="store_true", help="skip the profile-likelihood intervals"
    )
    p.add_argument(
        "--batch",
        metavar="NAME",
        help="the print batch the units came from, recorded in AS_BUILT.json (correct pools "
        "only files of one batch)",
    )
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    add_output_file(p, "AS_BUILT.json")
    add_accept_units(p, "the calibration CSV and the curves")
    p.set_defaults(handler=run)


def _add_reference_options(p):
    """The options of the angle reference's prior."""
    p.add_argument(
        "--conditions",
        metavar="COND.toml",
        help="operating conditions ([conditions] TOML) whose reference_zero_deg and "
        "reference_twist_deg are the prior std of the reference's zero offsets and twist "
        "(default 1.5°, 1.5°, 0.5°)",
    )
    p.add_argument(
        "--reference-zero",
        choices=("free", "fixed"),
        default="free",
        help="free (default): fit each unit's reference zero offsets and twist; fixed: take "
        "the reference as exact (a known mechanical zero)",
    )


def run(args):
    """Identify, write and print the summary; returns the exit code."""
    from reflector_opt.workflow._identify import identify

    inputs = {"data": args.data, "--design": args.design, "--tolerances": args.tolerances}
    inputs["--conditions"] = args.conditions
    inputs.update({f"--curve {c}": c.partition("=")[2] or None for c in args.curve})
    refuse_output_over_inputs(args.output, inputs)
    with progress_for(args) as progress:
        run = identify(
            args.data,
            design=args.design,
            curves=args.curve,
            tolerances=args.tolerances,
            reference_sigma_deg=args.reference_sigma,
            reference_zero=args.reference_zero,
            conditions=args.conditions,
            profiles=not args.no_profiles,
            batch=args.batch,
            progress=progress,
            accept_units=args.accept_units,
        ).write(args.output)
    return print_run(args, run, [args.output])
