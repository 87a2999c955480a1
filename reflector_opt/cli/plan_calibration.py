"""``reflector-opt plan-calibration [DESIGN.json] [--forms F,…] [--patterns P,…] [--sizes N,…]
[--units N] [--seed N] [--within X] [--speed DEG_S] [--dwell S] [-o DIR]``.

Predicts each calibration form's error against the number and pattern of poses on built units,
recommends the smallest plan within a fraction of the Cramér–Rao floor, estimates its motion
time and writes the plan (CSV of poses), the table (JSON) and the curves (PNG).
"""

from __future__ import annotations

import argparse

from reflector_opt.cli.arguments import (
    DEFAULT_OUT,
    add_output_folder,
    count,
    number,
    output_folder,
    seed,
)
from reflector_opt.cli.output import folder_lines
from reflector_opt.util.limits import MAX_POSES


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
            "within a fraction of the Cramér–Rao floor and write it as a CSV of poses."
        ),
    )
    p.add_argument("design", metavar="DESIGN.json", nargs="?", help="default: the built-in design")
    p.add_argument("--forms", type=_names, help="comma-separated (default eq6,auto,physical)")
    p.add_argument(
        "--patterns", type=_names, help="comma-separated (default raster,grid,sobol,spiral)"
    )
    p.add_argument(
        "--sizes",
        type=_sizes,
        help="comma-separated pose counts (default 25,50,100,200,400,1000,4000,16000)",
    )
    p.add_argument("--units", type=count(1, 100), default=3, help="built units (default 3)")
    p.add_argument(
        "--seed", type=seed, default=0, metavar="N", help="seed of units and noise (default 0)"
    )
    p.add_argument(
        "--within",
        type=number(0.0, 10.0),
        default=0.10,
        help="allowed excess over the floor for the recommendation (default 0.10)",
    )
    p.add_argument(
        "--speed",
        type=number(0.0, 1e4, "°/s", low_open=True),
        default=10.0,
        help="rig speed along the path, degrees per second (default 10)",
    )
    p.add_argument(
        "--dwell",
        type=number(0.0, 3600.0, "s"),
        default=0.5,
        help="time held at each pose, seconds (default 0.5)",
    )
    add_output_folder(p, f"{DEFAULT_OUT}/calibration_plan", "the plan, its table and curves")
    p.set_defaults(handler=run)


def run(args):
    """Plan, write plan.csv, plan.json and plan.png, print the table; returns the exit code."""
    from reflector_opt.calibration.files import write_csv
    from reflector_opt.calibration.plans import PATTERNS, make_plan
    from reflector_opt.design import default_design, load_design
    from reflector_opt.report.plots import calibration_plan_figure, save_figure
    from reflector_opt.tolerance.planning import (
        FORMS,
        SIZES,
        motion_time_s,
        predict_plans,
        recommend,
    )
    from reflector_opt.util.atomic import atomic_folder
    from reflector_opt.util.fileio import write_json

    design = default_design() if args.design is None else load_design(args.design)
    out = output_folder(args.out)
    study = predict_plans(
        design,
        forms=args.forms or FORMS,
        patterns=args.patterns or PATTERNS,
        sizes=args.sizes or SIZES,
        n_units=args.units,
        seed=args.seed,
    )
    best = recommend(study, args.within)
    summary = study.to_dict()
    summary["recommended"] = None
    names = []
    with atomic_folder(out, args.argv) as work:
        if best is not None:
            plan = make_plan(design.workspace, best.pattern, best.n_poses, seed=args.seed)
            seconds = motion_time_s(plan, args.speed, args.dwell)
            summary["recommended"] = {
                **best.to_dict(study.floor_rms_deg),
                "speed_deg_s": args.speed,
                "dwell_s": args.dwell,
                "motion_time_s": seconds,
            }
            rows = ((i + 1, repr(float(p)), repr(float(r))) for i, (p, r) in enumerate(plan))
            write_csv(work / "plan.csv", ("pose", "pitch_deg", "roll_deg"), rows)
            names.append("plan.csv")
        write_json(work / "plan.json", summary)
        save_figure(calibration_plan_figure(study), work / "plan.png")
        names += ["plan.json", "plan.png"]
    print(format_summary(summary))
    print(folder_lines(out, names, args.started))
    return 0


def format_summary(summary):
    """The table of predictions and the recommendation, as text."""
    floor = summary["floor_rms_deg"]
    lines = [
        f"predicted calibration error over {summary['n_units']} built units (seed "
        f"{summary['seed']}); Cramér–Rao floor RMS pitch {floor['pitch']:.4f}°, roll "
        f"{floor['roll']:.4f}°",
        f"  {'pattern':<8}{'poses':>7}  {'form':<9}{'RMS pitch':>10}{'RMS roll':>10}"
        f"{'× floor':>14}{'max':>16}",
    ]
    for p in summary["predictions"]:
        rms, ratio, peak = p["rms_deg"], p["floor_ratio"], p["max_deg"]
        lines.append(
            f"  {p['pattern']:<8}{p['n_poses']:>7}  {p['form']:<9}{rms['pitch']:>9.4f}°"
            f"{rms['roll']:>9.4f}°{ratio['pitch']:>7.2f}/{ratio['roll']:<5.2f}"
            f"{peak['pitch']:>8.3f}°/{peak['roll']:.3f}°"
        )
    best = summary["recommended"]
    if best is None:
        lines.append("no plan comes within the requested fraction of the floor")
    else:
        lines.append(
            f"recommended: {best['form']} on a {best['n_poses']}-pose {best['pattern']} "
            f"({best['floor_ratio']['pitch']:.2f}× / {best['floor_ratio']['roll']:.2f}× the "
            f"floor); motion {best['motion_time_s'] / 60:.1f} min at {best['speed_deg_s']:g}°/s "
            f"with {best['dwell_s']:g} s per pose"
        )
    return "\n".join(lines)
