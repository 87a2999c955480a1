"""``reflector-opt optimise [--config FILE.toml] [--out DIR] [--seed N] [--surface PRESET]
[--starts N] [--workers N] [--pareto] [--tolerances FILE.toml] [--scheduler ADDRESS]
[--no-report] [--quiet]``."""

from __future__ import annotations

import contextlib
import sys
from dataclasses import replace
from pathlib import Path

from reflector_opt.cli.arguments import count, seed
from reflector_opt.cli.tolerance import executor_factory
from reflector_opt.model.surface import DEFAULT_MATERIAL, MATERIALS, get_material
from reflector_opt.optimise import optimise
from reflector_opt.optimise.config import OptimiseConfig, load_config
from reflector_opt.optimise.pareto import pareto_front
from reflector_opt.optimise.robust import front_yield, robust_optimise
from reflector_opt.optimise.search import MAX_STARTS
from reflector_opt.report.plots import pareto_figure, save_figure
from reflector_opt.report.report import write_design_outputs
from reflector_opt.tolerance.config import load_tolerance_config
from reflector_opt.tolerance.executors import reused
from reflector_opt.util.errors import InputError
from reflector_opt.util.fileio import write_json
from reflector_opt.util.limits import MAX_WORKERS
from reflector_opt.util.progress import ProgressLine


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
    p.add_argument("--out", metavar="DIR", default="cad_out", help="output folder (cad_out)")
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
        help="skip the report and the printable parts (report.md/.html, STL, 3MF)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress line")
    p.set_defaults(handler=run)


def run(args):
    """Optimise, write the outputs and print a summary; returns the exit code."""
    config = load_config(args.config) if args.config else OptimiseConfig()
    if args.surface is not None:
        config = replace(
            config, problem=replace(config.problem, surface=get_material(args.surface))
        )
    seed = config.seed if args.seed is None else args.seed
    if args.workers is not None:
        config = replace(config, budget=replace(config.budget, workers=args.workers))
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out}: exists and is not a folder")
    tolerance = load_tolerance_config(args.tolerances) if args.tolerances else None
    if args.starts > 1 and tolerance is not None:
        raise InputError("--starts: not with --tolerances (each robust round runs one search)")
    if args.scheduler and tolerance is None and args.starts == 1:
        raise InputError(
            "--scheduler runs the searches of --starts and the tolerance studies: "
            "give --starts N or --tolerances FILE.toml"
        )
    studies = (
        contextlib.nullcontext()
        if tolerance is None
        else reused(executor_factory(args.scheduler, tolerance.run.workers))
    )
    searches = None
    if args.starts > 1 or args.scheduler:
        searches = executor_factory(args.scheduler, config.budget.workers)
    robust = front = None
    with ProgressLine(enabled=False if args.quiet else None) as progress, studies as factory:
        if tolerance is None:
            result = optimise(
                config.problem,
                seed=seed,
                budget=config.budget,
                progress=progress,
                starts=args.starts,
                executor=searches,
            )
        else:
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
        if args.pareto:
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
    result.design.save(out / "design.json")
    written = [out / "design.json"]
    if front is not None:
        write_json(out / "pareto.json", front.to_dict())
        save_figure(pareto_figure(front), out / "pareto.png")
        written += [out / "pareto.json", out / "pareto.png"]
    cad = None
    if not args.no_report:
        with ProgressLine(enabled=False if args.quiet else None) as progress:
            report_files, cad = write_design_outputs(
                result.design, out, seed=seed, progress=progress
            )
        written += report_files[:2]
    print(format_summary(result))
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
    print("\n".join(f"wrote {path}" for path in written))
    if cad is not None:
        print(cad.summary())
    return 0


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
        f"{robust.tolerance.run.seed}): {verdict} after {len(robust.rounds)} round(s), "
        f"{robust.seconds:.1f} s",
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


def _margin(record):
    return "∞" if record["margin"] is None else f"{record['margin']:.1f}"


def format_summary(result, written=()):
    """Human-readable lines for an :class:`~reflector_opt.optimise.OptimisationResult`."""
    p = result.design.predicted
    m = p["metrics"]
    r = p["metrics"]["resolution_deg"]
    refl = result.design.reflector
    lines = [
        f"optimised design (seed {result.seed}, "
        f"{sum(result.evaluations.values())} model evaluations, "
        f"{sum(result.seconds.values()):.1f} s)",
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
        "  constraints met on the workspace grid; margins: "
        f"distance {c['distance_margin_mm']['margin']:.3f} mm, "
        f"wall {c['wall_mm']['margin']:.3f} mm, "
        f"sensor envelope {c['sensor_envelope_mm']['margin']:.3f} mm, "
        f"reflector envelope {c['reflector_envelope_mm']['margin']:.3f} mm, "
        f"uniqueness {_margin(c['separation_sigma'])} σ_V"
    )
    lines += [f"wrote {path}" for path in written]
    return "\n".join(lines)
