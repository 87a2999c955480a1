"""``reflector-opt plan-calibration [DESIGN.json] [--for calibration|identification]
[--forms F,…] [--patterns P,…] [--sizes N,…] [--units N] [--seed N] [--within X]
[--temperature-range K] [--target-std X] [--candidate-step DEG] [--truth built|model]
[--no-check] [--speed DEG_S] [--dwell S] [--json] [-o DIR]``.

For a calibration (the default), predicts each calibration form's error against the number and
pattern of poses on built units, recommends the smallest plan within a fraction of the
Cramér–Rao floor, estimates its motion time and writes the plan (CSV of poses), the table
(JSON) and the curves (PNG). With ``--temperature-range K`` it also simulates, on built units,
the recommended plan at the calibration temperature T0 plus Sobol poses at T0 + K (or at
T0 − K and T0 + K), and says how many poses at which temperatures keep the compensated
calibration within ``--within`` of its error at T0 over ±K
(:mod:`reflector_opt.tolerance._thermalplan`); those poses go to plan_temperature.csv.

For identification (``--for identification``), chooses the D-optimal poses for a unit's
as-built parameters (:mod:`reflector_opt.asbuilt._planstudy`), the number that brings every
determinable parameter to ``--target-std`` of its prior std, compares the D-optimal plans
with Sobol points and grids of the same sizes, checks them by identifying simulated units,
sets the calibration forms' error on the same units beside them, and writes the plan (CSV)
and the table (JSON).
"""

from __future__ import annotations

import argparse

from reflector_opt.cli._arguments import DEFAULT_OUT, add_output_folder, count, number, seed
from reflector_opt.cli._command import call_into_folder, print_run
from reflector_opt.util._limits import MAX_POSES
from reflector_opt.workflow._plan_calibration import (
    DEFAULT_DWELL_S,
    DEFAULT_SPEED_DEG_S,
    DEFAULT_UNITS,
    DEFAULT_WITHIN,
)


def _names(text):
    names = tuple(part.strip() for part in text.split(",") if part.strip())
    if not names:  # an empty list would silently stand for the default one
        raise argparse.ArgumentTypeError(f"expected a comma-separated list, got {text!r}")
    return names


def _sizes(text):
    parse = count(4, MAX_POSES)
    return tuple(parse(part) for part in _names(text))


def register(subparsers):
    """Add the ``plan-calibration`` subcommand."""
    p = subparsers.add_parser(
        "plan-calibration",
        help="predicted calibration error against the number and pattern of poses",
        description=(
            "Predict the RMS and maximum calibration error of each form (eq6, auto, physical) "
            "on plans of each pattern (the paper's raster, coarse grids, Sobol points, a "
            "spiral) and size, against built units of the design; recommend the smallest plan "
            "within a fraction of the Cramér–Rao floor and write it as a CSV of poses. With "
            "--for identification, choose the D-optimal poses for identifying a unit's "
            "as-built parameters and the number that brings each determinable one to "
            "--target-std of its prior std, beside Sobol points and grids."
        ),
    )
    p.add_argument("design", metavar="DESIGN.json", nargs="?", help="default: the built-in design")
    p.add_argument(
        "--forms",
        type=_names,
        help="comma-separated (default eq6,auto,physical; for identification the forms set "
        "beside it, default auto,physical)",
    )
    p.add_argument(
        "--patterns",
        type=_names,
        help="comma-separated (default raster,grid,sobol,spiral; for identification "
        "d-optimal,sobol,grid)",
    )
    p.add_argument(
        "--sizes",
        type=_sizes,
        help="comma-separated pose counts (default 25,50,100,200,400,1000,4000,16000; for "
        "identification 25,50,100,200)",
    )
    p.add_argument(
        "--units",
        type=count(1, 100),
        default=DEFAULT_UNITS,
        help=f"built units (default {DEFAULT_UNITS})",
    )
    p.add_argument(
        "--seed", type=seed, default=0, metavar="N", help="seed of units and noise (default 0)"
    )
    p.add_argument(
        "--within",
        type=number(0.0, 10.0),
        default=DEFAULT_WITHIN,
        help=f"allowed excess over the floor for the recommendation (default {DEFAULT_WITHIN:.2f})",
    )
    _register_rig(p)
    p.add_argument(
        "--json",
        action="store_true",
        help="print the summary (the table, the recommendation and the files) as JSON",
    )
    _register_identification(p)
    add_output_folder(p, f"{DEFAULT_OUT}/calibration_plan", "the plan, its table and curves")
    p.set_defaults(handler=run)


def _register_rig(p):
    """``--speed`` and ``--dwell``: the rig's motion, for the plan's time; and
    ``--temperature-range``, the temperatures the rig records the unit at."""
    p.add_argument(
        "--temperature-range",
        type=number(1.0, 60.0, "K"),
        default=None,
        metavar="K",
        help="calibration: also plan the poses at other temperatures for a unit used within "
        "±K kelvin of its calibration temperature (a simulation on built units; the "
        "recommended plan's form, auto for physical)",
    )
    p.add_argument(
        "--speed",
        type=number(0.0, 1e4, "°/s", low_open=True),
        default=DEFAULT_SPEED_DEG_S,
        help=f"rig speed along the path, degrees per second (default {DEFAULT_SPEED_DEG_S:g})",
    )
    p.add_argument(
        "--dwell",
        type=number(0.0, 3600.0, "s"),
        default=DEFAULT_DWELL_S,
        help=f"time held at each pose, seconds (default {DEFAULT_DWELL_S:g})",
    )


def _register_identification(p):
    """``--for`` and the options of ``--for identification``."""
    p.add_argument(
        "--for",
        dest="purpose",
        choices=("calibration", "identification"),
        default="calibration",
        help="plan a calibration's poses (default) or an as-built identification's",
    )
    p.add_argument(
        "--target-std",
        type=number(0.0, 1.0, low_open=True),
        default=None,
        metavar="X",
        help="identification: posterior std to reach, as a fraction of the prior std (default 0.5)",
    )
    p.add_argument(
        "--candidate-step",
        type=number(0.25, 15.0, "°"),
        default=None,
        metavar="DEG",
        help="identification: step of the candidate grid, degrees (default 1)",
    )
    p.add_argument(
        "--truth",
        choices=("built", "model"),
        default=None,
        help="identification: check on built units with exact optics (default) or on units "
        "of the identification's own model",
    )
    p.add_argument(
        "--no-check",
        action="store_true",
        default=None,
        help="identification: the Fisher prediction only, no simulated identification",
    )


def run(args):
    """Plan, write plan.csv (and plan_temperature.csv), plan.json and plan.png, print the
    table; returns the exit code."""
    from reflector_opt.workflow._plan_calibration import plan_calibration

    run = call_into_folder(
        args,
        plan_calibration,
        args.design,
        purpose=args.purpose,
        forms=args.forms,
        patterns=args.patterns,
        sizes=args.sizes,
        units=args.units,
        seed=args.seed,
        within=args.within,
        temperature_range_k=args.temperature_range,
        speed_deg_s=args.speed,
        dwell_s=args.dwell,
        target_std=args.target_std,
        candidate_step_deg=args.candidate_step,
        truth=args.truth,
        check=None if args.no_check is None else not args.no_check,
    )
    return print_run(args, run, folder=args.out)
