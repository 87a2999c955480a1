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
(:mod:`reflector_opt.tolerance.thermalplan`); those poses go to plan_temperature.csv.

For identification (``--for identification``), chooses the D-optimal poses for a unit's
as-built parameters (:mod:`reflector_opt.asbuilt.planning`), the number that brings every
determinable parameter to ``--target-std`` of its prior std, compares the D-optimal plans
with Sobol points and grids of the same sizes, checks them by identifying simulated units,
sets the calibration forms' error on the same units beside them, and writes the plan (CSV)
and the table (JSON).
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
from reflector_opt.cli.output import folder_lines, print_json, progress_for
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
        default=10.0,
        help="rig speed along the path, degrees per second (default 10)",
    )
    p.add_argument(
        "--dwell",
        type=number(0.0, 3600.0, "s"),
        default=0.5,
        help="time held at each pose, seconds (default 0.5)",
    )


#: Options that only a plan for identification takes.
_IDENTIFICATION_ONLY = ("target_std", "candidate_step", "truth", "no_check")


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
    from reflector_opt.util.errors import InputError

    if args.purpose == "identification":
        if args.temperature_range is not None:
            raise InputError("--temperature-range applies to --for calibration only")
        return run_identification(args)
    given = [name for name in _IDENTIFICATION_ONLY if getattr(args, name) is not None]
    if given:
        option = "--" + given[0].replace("_", "-")
        raise InputError(f"{option} applies to --for identification only")
    from reflector_opt.calibration.plans import PATTERNS
    from reflector_opt.design import default_design, load_design
    from reflector_opt.tolerance.planning import (
        FORMS,
        SIZES,
        predict_plans,
        recommend,
    )
    from reflector_opt.util.atomic import atomic_folder

    design = default_design() if args.design is None else load_design(args.design)
    out = output_folder(args.out)
    with progress_for(args) as progress:
        study = predict_plans(
            design,
            forms=args.forms or FORMS,
            patterns=args.patterns or PATTERNS,
            sizes=args.sizes or SIZES,
            n_units=args.units,
            seed=args.seed,
            progress=progress,
        )
        best = recommend(study, args.within)
        thermal = _plan_temperature(design, study, args, progress)
    with atomic_folder(out, args.argv) as work:
        summary, names = _write_plan(work, design, study, best, thermal, args)
    _print_result(args, summary, format_summary, out, names)
    return 0


def _write_plan(work, design, study, best, thermal, args):
    """Write plan.csv, plan_temperature.csv, plan.json and plan.png into ``work``; the
    summary and the names written."""
    from reflector_opt.calibration.files import write_csv
    from reflector_opt.calibration.plans import make_plan
    from reflector_opt.report.plots import calibration_plan_figure, save_figure
    from reflector_opt.tolerance.planning import motion_time_s
    from reflector_opt.util.fileio import write_json

    summary = study.to_dict()
    summary["recommended"] = None
    names = []
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
    if args.temperature_range is not None:  # None: no recommended plan to extend
        summary["temperature"] = thermal and _write_temperature(work, design, thermal, args)
        if thermal is not None and summary["temperature"]["recommended"] is not None:
            names.append("plan_temperature.csv")
    write_json(work / "plan.json", summary)
    save_figure(calibration_plan_figure(study), work / "plan.png")
    names += ["plan.json", "plan.png"]
    return summary, names


def _plan_temperature(design, study, args, progress):
    """The temperature study on the plan to extend, or None (not asked, or no plan)."""
    if args.temperature_range is None:
        return None
    from reflector_opt.calibration.plans import make_plan
    from reflector_opt.tolerance.thermalplan import plan_temperature, plan_to_extend

    chosen = plan_to_extend(study, args.within)
    if chosen is None:
        return None
    form, pattern, n_poses = chosen
    return plan_temperature(
        design,
        make_plan(design.workspace, pattern, n_poses, seed=args.seed),
        change_k=args.temperature_range,
        form=form,
        pattern=pattern,
        n_units=args.units,
        seed=args.seed,
        progress=progress,
    )


def _write_temperature(work, design, study, args):
    """Write plan_temperature.csv (if a layout is recommended); its summary, JSON-ready."""
    from reflector_opt.calibration.files import write_csv
    from reflector_opt.tolerance.planning import motion_time_s
    from reflector_opt.tolerance.thermalplan import recommend_thermal, thermal_poses

    summary = study.to_dict()
    pick = recommend_thermal(study, args.within)
    summary["recommended"] = None
    if pick is not None:
        poses = thermal_poses(design, pick, args.seed)
        per_temperature = motion_time_s(poses[: pick.n_poses, :2], args.speed, args.dwell)
        summary["recommended"] = {
            **pick.to_dict(),
            "motion_time_s": per_temperature * len(pick.changes_k),
        }
        rows = (
            (i + 1, repr(float(p)), repr(float(r)), repr(float(dt)))
            for i, (p, r, dt) in enumerate(poses)
        )
        header = ("pose", "pitch_deg", "roll_deg", "temperature_change_k")
        write_csv(work / "plan_temperature.csv", header, rows)
    return summary


def _print_result(args, summary, format_text, out, names):
    """The summary as text and the files written, or with ``--json`` all of it as JSON."""
    if args.json:
        print_json({**summary, "folder": str(out), "files": [str(out / n) for n in names]})
        return
    print(format_text(summary))
    print(folder_lines(out, names, args.started))


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
    return "\n".join(lines + temperature_lines(summary))


def temperature_lines(summary):
    """The temperature study's table and recommendation, as text lines ([] if not asked)."""
    if "temperature" not in summary:
        return []
    thermal = summary["temperature"]
    if thermal is None:
        return ["temperature: no recommended plan to extend (try a larger --within)"]
    changes = ", ".join(f"{dt:+g}" for dt in thermal["validation_k"])
    lines = [
        f"temperature (use within ±{thermal['change_k']:g} K of the calibration's T0; "
        f"{thermal['form']} on the {thermal['base_poses']}-pose {thermal['pattern']} at T0, "
        f"{thermal['n_units']} built units); RMS error over the same poses' at T0, at ΔT = "
        f"{changes} K (worse of pitch, roll):",
        f"  {'the plan alone, uncompensated':<31}" + _ratio_cells(thermal["uncompensated_ratio"]),
    ]
    for p in thermal["predictions"]:
        at = ", ".join(f"{dt:+g}" for dt in p["changes_k"])
        label = f"{p['n_poses']} poses at T0 {at} K"
        lines.append(f"  {label:<31}" + _ratio_cells(p["ratio"]))
    pick = thermal["recommended"]
    if pick is None:
        lines.append("temperature: no layout tried comes within the requested fraction")
        return lines
    at = " and ".join(f"T0 {dt:+g} K" for dt in pick["changes_k"])
    worst = max(max(row) for row in pick["ratio"])
    lines.append(
        f"temperature: the plan at T0, then {pick['n_poses']} Sobol poses at {at} "
        f"(plan_temperature.csv; {worst:.2f}× their T0 error at worst, uncompensated "
        f"{max(max(row) for row in thermal['uncompensated_ratio']):.2f}×; motion "
        f"{pick['motion_time_s'] / 60:.1f} min)"
    )
    return lines


def _ratio_cells(ratio):
    return "".join(f"{max(row):>7.2f}" for row in ratio)


def run_identification(args):
    """Plan for identification, write plan.csv and plan.json, print the tables."""
    from reflector_opt.calibration.files import write_csv
    from reflector_opt.design import default_design, load_design
    from reflector_opt.tolerance.planning import motion_time_s
    from reflector_opt.util.atomic import atomic_folder
    from reflector_opt.util.errors import InputError
    from reflector_opt.util.fileio import write_json

    design = default_design() if args.design is None else load_design(args.design)
    out = output_folder(args.out)
    check = not args.no_check
    truth = args.truth or "built"
    if args.forms is not None and not (check and truth == "built"):
        raise InputError("--forms: the calibration forms are compared on built units only")
    forms = args.forms if args.forms is not None else ("auto", "physical")
    with progress_for(args) as progress:
        study = _plan_identification(design, args, check, truth, forms, progress)
    summary = study.to_dict(args.within)
    names = []
    with atomic_folder(out, args.argv) as work:
        if study.plan is not None:
            plan = study.plan.poses_deg
            summary["recommended"].update(
                speed_deg_s=args.speed,
                dwell_s=args.dwell,
                motion_time_s=motion_time_s(plan, args.speed, args.dwell),
            )
            rows = ((i + 1, repr(float(p)), repr(float(r))) for i, (p, r) in enumerate(plan))
            write_csv(work / "plan.csv", ("pose", "pitch_deg", "roll_deg"), rows)
            names.append("plan.csv")
        write_json(work / "plan.json", summary)
        names.append("plan.json")
    _print_result(args, summary, format_identification, out, names)
    return 0


def _plan_identification(design, args, check, truth, forms, progress):
    """:func:`~reflector_opt.asbuilt.planning.plan_identification` with the command's options;
    its step messages shown through ``progress``."""
    from reflector_opt.asbuilt.planning import (
        CANDIDATE_STEP_DEG,
        PATTERNS,
        SIZES,
        plan_identification,
    )
    from reflector_opt.asbuilt.uncertainty import DETERMINED_RATIO

    return plan_identification(
        design,
        sizes=args.sizes or SIZES,
        patterns=args.patterns or PATTERNS,
        target=DETERMINED_RATIO if args.target_std is None else args.target_std,
        n_units=args.units if check else 0,
        seed=args.seed,
        truth=truth,
        compare_forms=forms if check and truth == "built" else (),
        candidate_step_deg=args.candidate_step or CANDIDATE_STEP_DEG,
        progress=lambda message: progress(0.0, message),
    )


def _with_unit(name, value):
    """A parameter's value with its unit, from the name's suffix."""
    if name.endswith("_mm"):
        return f"{value * 1000:.3g} µm"
    if name.endswith("_deg"):
        return f"{value:.3g}°"
    if name.endswith("_v"):
        return f"{value * 1000:.3g} mV"
    if name.endswith("gain"):
        return f"{value * 100:.3g} %"
    return f"{value:.3g}"


def _cell(value, width, digits=2):
    return f"{'—' if value is None else f'{value:.{digits}f}':>{width}}"


def format_identification(summary):
    """The per-parameter table, the patterns' table and the comparison, as text."""
    target = summary["target_std_ratio"]
    candidates = summary["candidates"]
    lines = [
        f"plan for identification: {len(summary['parameters'])} as-built parameters of a unit "
        f"(prior: the tolerance model); {candidates['n_poses']} candidate poses on a "
        f"{candidates['step_deg']:g}° grid; target: posterior std ≤ {target:g} × prior std",
        f"  {'parameter':<32}{'prior std':>11}{'all cand.':>10}{'poses':>7}{'plan':>7}"
        f"{'achieved':>10}",
    ]
    for p in summary["parameters"]:
        lines.append(
            f"  {p['name']:<32}{_with_unit(p['name'], p['prior_std']):>11}"
            f"{_cell(p['ratio_all_candidates'], 10)}"
            f"{'—' if p['poses_needed'] is None else p['poses_needed']:>7}"
            f"{_cell(p.get('plan_ratio'), 7)}{_cell(p.get('achieved_ratio'), 10)}"
        )
    lines.append(
        "  (ratios: posterior / prior std; 'achieved': RMS error of the simulated units' "
        "identification / prior std)"
    )
    lines += _recommendation_lines(summary)
    lines += _pattern_lines(summary)
    lines += _within_lines(summary)
    return "\n".join(lines)


def _recommendation_lines(summary):
    best = summary["recommended"]
    if best is None:
        return ["no parameter reaches the target even with every candidate pose"]
    line = (
        f"recommended: {best['n_poses']} D-optimal poses bring the {len(best['determinable'])} "
        f"determinable parameters to the target; motion {best['motion_time_s'] / 60:.1f} min "
        f"at {best['speed_deg_s']:g}°/s with {best['dwell_s']:g} s per pose"
    )
    lines = [line]
    if best["check"] is not None:
        ratio = best["check"]["floor_ratio"]
        lines.append(
            f"checked on {summary['n_units']} {summary['truth']} units: angle RMS "
            f"{ratio['pitch']:.2f}× / {ratio['roll']:.2f}× the Cramér–Rao floor"
        )
    return lines


def _pattern_lines(summary):
    target = summary["target_std_ratio"]
    lines = [
        f"  {'pattern':<10}{'poses':>6}{'log det':>9}{'≤ target':>10}{'angle × floor':>16}",
    ]
    for row in summary["patterns"]:
        ratio = (row["check"] or {}).get("floor_ratio")
        angle = "—" if ratio is None else f"{ratio['pitch']:.2f}/{ratio['roll']:.2f}"
        lines.append(
            f"  {row['pattern']:<10}{row['n_poses']:>6}{row['log_det']:>9.2f}"
            f"{len(row['determined']):>10}{angle:>16}"
        )
    lines.append(
        f"  (log det: information over the prior, nats; ≤ target: parameters at most {target:g}"
        " × their prior std)"
    )
    return lines


def _within_lines(summary):
    table = summary["smallest_within_floor"]
    if not table["identification"]:
        return []
    patterns = list(table["identification"])
    lines = [
        f"smallest plan within {summary['within'] * 100:g} % of the Cramér–Rao floor (angle "
        "RMS, both angles; — : none of the sizes tried)",
        f"  {'method':<16}" + "".join(f"{p:>11}" for p in patterns),
    ]
    for method, row in table.items():
        cells = "".join(
            f"{'—' if row.get(p) is None else row[p]:>11}" if p in row else f"{'':>11}"
            for p in patterns
        )
        lines.append(f"  {method:<16}{cells}")
    return lines
