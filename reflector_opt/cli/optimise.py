"""``reflector-opt optimise [--config FILE.toml] [-o DIR] [--seed N] [--surface PRESET]
[--sensor PARTS] [--starts N] [--workers N] [--pareto] [--tolerances FILE.toml]
[--scheduler ADDRESS] [--no-report] [-q] [-v]``."""

from __future__ import annotations

import contextlib
import sys
from dataclasses import replace

from reflector_opt.cli.arguments import DEFAULT_OUT, add_output_folder, count, output_folder, seed
from reflector_opt.cli.evaluate import calibration_lines
from reflector_opt.cli.output import cad_files, folder_lines, progress_for
from reflector_opt.cli.tolerance import executor_factory
from reflector_opt.model.surface import DEFAULT_MATERIAL, MATERIALS, get_material
from reflector_opt.util.errors import InputError
from reflector_opt.util.limits import MAX_STARTS, MAX_WORKERS


def register(subparsers):
    """Add the ``optimise`` subcommand."""
    p = subparsers.add_parser(
        "optimise",
        help="optimise the reflector and sensor placement; writes design.json",
        description=(
            "Find the reflector radius, centre offset and sensor placement with the best "
            "worst-case angular resolution that keeps every sensor inside its usable range "
            "and meets the envelope, wall and no-fold constraints. With no options it runs "
            "on the built-in defaults and writes cad_out/design.json."
        ),
    )
    p.add_argument("--config", metavar="FILE.toml", help="settings (see docs/optimiser.md)")
    add_output_folder(p, DEFAULT_OUT, "design.json, the report and the parts")
    p.add_argument("--seed", type=seed, metavar="N", help="seed of the search (config or 0)")
    p.add_argument(
        "--surface",
        metavar="PRESET",
        choices=sorted(MATERIALS),
        help=(
            "the reflector's surface to design for: "
            + ", ".join(
                f"{m.name} (ρ {m.reflectance}, f {m.specular_fraction})" for m in MATERIALS.values()
            )
            + f"; default the config's or {DEFAULT_MATERIAL}"
        ),
    )
    p.add_argument(
        "--sensor",
        metavar="PARTS",
        help=(
            "choose the sensor part: auto (every part of the sensor catalogue), part names or "
            "PARTS.toml catalogue files, separated by commas; each part that fits the unit is "
            "optimised (in parallel on --workers processes, or on --scheduler) and the best "
            "kept; replaces the config's [sensor]"
        ),
    )
    p.add_argument(
        "--starts",
        type=count(1, MAX_STARTS),
        default=1,
        metavar="N",
        help="independent searches from seeds derived from --seed, the best one kept (1)",
    )
    p.add_argument(
        "--workers",
        type=count(1, MAX_WORKERS),
        metavar="N",
        help="worker processes of the search (config or 2)",
    )
    p.add_argument(
        "--pareto",
        action="store_true",
        help="also trace resolution against distance margin (pareto.json, pareto.png; slow)",
    )
    p.add_argument(
        "--tolerances",
        metavar="FILE.toml",
        help=(
            "optimise robustly against these tolerances (the file `tolerance --config` reads): "
            "the distance margin is raised until it covers [robust] coverage of built units; "
            "with --pareto, each point gets its yield"
        ),
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help=(
            "run the searches of --starts and the tolerance studies on a Dask scheduler, "
            "e.g. tcp://host:8786"
        ),
    )
    p.add_argument(
        "--no-report",
        action="store_true",
        help="skip the report, the predicted calibration errors and the printable parts",
    )
    p.set_defaults(handler=run)


def run(args):
    """Optimise, write the outputs and print a summary; returns the exit code."""
    # The report, the figures, the Pareto front and the tolerance studies are imported only
    # when asked for: together they cost seconds of start-up that `--no-report` need not pay.
    from reflector_opt.optimise.config import OptimiseConfig, load_config
    from reflector_opt.optimise.search import optimise
    from reflector_opt.tolerance.executors import reused
    from reflector_opt.util.atomic import atomic_folder

    config = OptimiseConfig() if args.config is None else load_config(args.config)
    if args.surface is not None:
        config = replace(
            config, problem=replace(config.problem, surface=get_material(args.surface))
        )
    seed = config.seed if args.seed is None else args.seed
    if args.workers is not None:
        config = replace(config, budget=replace(config.budget, workers=args.workers))
    out = output_folder(args.out)
    tolerance = None
    if args.tolerances is not None:
        from reflector_opt.tolerance.config import load_tolerance_config

        tolerance = load_tolerance_config(args.tolerances)
    if args.starts > 1 and tolerance is not None:
        raise InputError("--starts: not with --tolerances (each robust round runs one search)")
    parts = _sensor_parts(args, tolerance)
    if len(parts) == 1:
        from reflector_opt.optimise.sensor_choice import part_problem

        config = replace(config, problem=part_problem(config.problem, parts[0]))
    if args.scheduler is not None and tolerance is None and args.starts == 1 and len(parts) < 2:
        raise InputError(
            "--scheduler runs the searches of --starts or of a --sensor list and the tolerance "
            "studies: give --starts N or --tolerances FILE.toml, or --sensor with several parts"
        )
    studies = (
        contextlib.nullcontext()
        if tolerance is None
        else reused(executor_factory(args.scheduler, tolerance.run.workers))
    )
    searches = None
    if args.starts > 1 or args.scheduler is not None:
        searches = executor_factory(args.scheduler, config.budget.workers)
    robust = front = None
    with progress_for(args) as progress, studies as factory:
        if len(parts) > 1:
            from reflector_opt.optimise.sensor_choice import choose_sensor

            result = choose_sensor(
                config.problem,
                parts,
                seed=seed,
                budget=config.budget,
                executor=searches,
                progress=progress,
            ).result
        elif tolerance is None:
            result = optimise(
                config.problem,
                seed=seed,
                budget=config.budget,
                progress=progress,
                starts=args.starts,
                executor=searches,
            )
        else:
            from reflector_opt.optimise.robust import robust_optimise

            robust = robust_optimise(
                config.problem,
                tolerance,
                options=config.robust,
                seed=seed,
                budget=config.budget,
                factory=factory,
                progress=progress,
            )
            result = robust.result
        if len(parts) == 1:
            from reflector_opt.optimise.sensor_choice import record_part

            result = record_part(result, parts[0], config.problem, seed)
        if args.pareto:
            from reflector_opt.optimise.pareto import pareto_front
            from reflector_opt.optimise.robust import front_yield

            front = pareto_front(
                config.problem,
                config.pareto_margins_mm,
                seed=seed,
                budget=config.budget,
                progress=progress,
            )
            if tolerance is not None:
                front = front_yield(
                    front, config.problem, tolerance, factory=factory, progress=progress
                )
    names, cad, predicted = ["design.json"], None, None
    with atomic_folder(out, args.argv) as work:
        result.design.save(work / "design.json")
        if front is not None:
            from reflector_opt.report.plots import pareto_figure, save_figure
            from reflector_opt.util.fileio import write_json

            write_json(work / "pareto.json", front.to_dict())
            save_figure(pareto_figure(front), work / "pareto.png")
            names += ["pareto.json", "pareto.png"]
        if not args.no_report:
            from reflector_opt.report.report import write_design_outputs
            from reflector_opt.tolerance.prediction import predicted_performance

            predicted = predicted_performance(result.design, seed=seed)
            with progress_for(args) as progress:
                report_files, cad = write_design_outputs(
                    result.design, work, seed=seed, progress=progress, predicted=predicted
                )
            names += [path.name for path in report_files]
    print(format_summary(result))
    if "sensor_choice" in result.design.predicted:
        from reflector_opt.optimise.sensor_choice import ranking_lines

        print("\n".join(ranking_lines(result.design.predicted["sensor_choice"])))
    if predicted is not None and predicted["calibration"] is not None:
        print("\n".join(calibration_lines(predicted["calibration"])))
    if robust is not None:
        print(format_robust(robust))
        if not robust.converged:
            print(
                "reflector-opt optimise: warning: the robust margin did not converge in "
                f"{len(robust.rounds)} rounds; design.json keeps the last round "
                "(raise [robust] max_rounds)",
                file=sys.stderr,
            )
    if front is not None:
        print(format_pareto(front))
    if cad is not None and cad.error is not None:
        print(cad.summary())
    written = [*(out / name for name in names), *cad_files(cad and cad.report, out)]
    print(folder_lines(out, written, args.started))
    return 0


def _sensor_parts(args, tolerance):
    """The parts of ``--sensor`` (none without it); several exclude the one-search options."""
    if args.sensor is None:
        return []
    from reflector_opt.model.catalogue import resolve_parts

    parts = resolve_parts(args.sensor)
    if len(parts) > 1:
        for given, option in (
            (tolerance is not None, "--tolerances"),
            (args.pareto, "--pareto"),
            (args.starts > 1, "--starts"),
        ):
            if given:
                raise InputError(
                    f"--sensor: {len(parts)} parts, not with {option}; choose the part first, "
                    f"then run {option} with --sensor PART"
                )
    return parts


def format_robust(robust):
    """Human-readable lines for a :class:`~reflector_opt.optimise.robust.RobustResult`."""
    coverage = f"{100 * robust.options.coverage:g} %"
    verdict = "covered" if robust.converged else "NOT covered"
    samples = robust.tolerance.run.samples
    basis = (
        f"95 % upper bound from {samples} sampled units"
        if robust.rounds[-1]["required_confidence"] is not None
        else f"sample quantile of {samples} units, too few for a 95 % bound"
    )
    lines = [
        f"robust margin (the loss in {coverage} of built units, {basis}, seed "
        f"{robust.tolerance.run.seed}): {verdict} after {len(robust.rounds)} round(s)",
        "  round  limit (mm)  margin (mm)  required (mm)  window yield [95 % interval]  "
        "resolution (°)",
    ]
    for r in robust.rounds:
        low, high = r["window_yield_interval"]
        lines.append(
            f"  {r['round']:>5}  {r['limit_mm']:>10.3f}  {r['margin_mm']:>11.3f}  "
            f"{r['required_mm']:>13.3f}  {100 * r['window_yield']:>5.1f} % "
            f"[{100 * low:.1f}–{100 * high:.1f} %]{'':>6}  {r['objective_deg']:.4f}"
        )
    return "\n".join(lines)


def format_pareto(front):
    """The Pareto front as a table, with the yield of each point once estimated."""
    with_yield = front.yield_basis is not None
    header = "  required (mm)  margin (mm)  pitch (°)  roll (°)"
    if with_yield:
        basis = front.yield_basis
        judged = "all targets" if basis["calibrated"] else "distance window"
        header += f"  yield ({judged}, {basis['samples']} units) [95 % interval]"
    lines = [f"Pareto front (seed {front.seed}):", header]
    for p in front.points:
        row = f"  {p.required_margin_mm:>13.3f}"
        if not p.feasible:
            lines.append(f"{row}  no design: {p.reason}")
            continue
        row += f"  {p.margin_mm:>11.3f}  {p.worst_pitch_deg:>9.4f}  {p.worst_roll_deg:>8.4f}"
        if with_yield:
            row += (
                f"  {100 * p.yield_fraction:.1f} % "
                f"[{100 * p.yield_low:.1f}–{100 * p.yield_high:.1f} %]"
            )
        lines.append(row)
    return "\n".join(lines)


def _deg(x):
    return "inf" if x is None else f"{x:.4f}°"


def _slack(record):
    return "∞" if record["margin"] is None else f"{record['margin']:.1f}"


def format_summary(result):
    """Human-readable lines for an :class:`~reflector_opt.optimise.OptimisationResult`."""
    p = result.design.predicted
    m = p["metrics"]
    r = p["metrics"]["resolution_deg"]
    refl = result.design.reflector
    lines = [
        f"optimised design (seed {result.seed}, "
        f"{sum(result.evaluations.values())} model evaluations)",
        f"  reflector: radius {refl.radius_mm:.3f} mm, centre "
        f"({', '.join(f'{c:.3f}' for c in refl.centre_mm)}) mm, "
        f"inner radius {refl.inner_radius_mm:.3f} mm",
    ]
    for s in result.design.sensors:
        lines.append(
            f"  {s.name}: position ({', '.join(f'{c:.3f}' for c in s.position_mm)}) mm, "
            f"axis ({', '.join(f'{c:.3f}' for c in s.axis)})"
        )
    lines.append(
        f"  worst-case 1σ resolution on the {m['grid_step_deg']}° grid: pitch "
        f"{_deg(r['pitch_worst'])}, roll {_deg(r['roll_worst'])} "
        f"(σ_V = {m['sigma_v'] * 1e3:.2f} mV)"
    )
    windows = ", ".join(
        f"{lo:.3f}–{hi:.3f} mm"
        for lo, hi in zip(m["distance_mm"]["min"], m["distance_mm"]["max"], strict=True)
    )
    lines.append(f"  distance windows: {windows}")
    if "baseline" in p:
        b = p["baseline"]["metrics"]["resolution_deg"]
        imp = p["improvement"]
        factor = "n/a" if imp["worst"] is None else f"{imp['worst']:.2f}×"
        lines.append(
            f"  default design: pitch {_deg(b['pitch_worst'])}, roll {_deg(b['roll_worst'])}; "
            f"improvement {factor}"
        )
    c = p["constraints"]
    lines.append(
        "  constraints met on the workspace grid; slack (how far inside each limit): "
        f"distance margin {c['distance_margin_mm']['margin']:.3f} mm, "
        f"wall {c['wall_mm']['margin']:.3f} mm, "
        f"sensor envelope {c['sensor_envelope_mm']['margin']:.3f} mm, "
        f"reflector envelope {c['reflector_envelope_mm']['margin']:.3f} mm, "
        f"uniqueness {_slack(c['separation_sigma'])} σ_V"
    )
    return "\n".join(lines)
