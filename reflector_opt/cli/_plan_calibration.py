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

from reflector_opt.cli._arguments import DEFAULT_OUT, add_output_folder
from reflector_opt.cli._command import call_into_folder, print_run
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._plan_calibration import PlanCalibrationOptions


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
    add_options(p, PlanCalibrationOptions)
    p.add_argument(
        "--json",
        action="store_true",
        help="print the summary (the table, the recommendation and the files) as JSON",
    )
    add_output_folder(p, f"{DEFAULT_OUT}/calibration_plan", "the plan, its table and curves")
    p.set_defaults(handler=run)


def run(args):
    """Plan, write plan.csv (and plan_temperature.csv), plan.json and plan.png, print the
    table; returns the exit code."""
    from reflector_opt.workflow._plan_calibration import plan_calibration

    run = call_into_folder(
        args, plan_calibration, args.design, options_of(args, PlanCalibrationOptions)
    )
    return print_run(args, run, folder=args.out)
