"""``reflector-opt optimise [--config FILE.toml] [-o DIR] [--seed N] [--surface PRESET]
[--sensor PARTS] [--conditions COND.toml] [--starts N] [--workers N] [--pareto]
[--drift-front] [--tolerances FILE.toml] [--scheduler ADDRESS] [--no-report] [--json] [-q]
[-v]``.

Parses the options and calls :func:`reflector_opt.workflow.optimise_run`, which makes the
run; prints its summary.
"""

from __future__ import annotations

import sys

from reflector_opt.cli.arguments import DEFAULT_OUT, add_output_folder, count, seed
from reflector_opt.cli.command import call_into_folder
from reflector_opt.cli.evaluate import calibration_lines
from reflector_opt.cli.output import folder_lines, print_json
from reflector_opt.model.surface import DEFAULT_MATERIAL, MATERIALS
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
    _add_design_arguments(p)
    _add_search_arguments(p)
    p.add_argument(
        "--no-report",
        action="store_true",
        help="skip the report, the predicted calibration errors and the printable parts",
    )
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(handler=run)


def _add_design_arguments(p):
    """``--surface``, ``--sensor`` and ``--conditions``: what the design is made of and the
    conditions it is used in."""
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
        "--conditions",
        metavar="COND.toml",
        help=(
            "operating conditions ([conditions] TOML, docs/conditions.md): optimise the "
            "worst-case total error in them instead of the white-noise resolution; replaces "
            "the config's [conditions]"
        ),
    )


def _add_search_arguments(p):
    """How the search runs: starts, workers, Pareto and drift fronts, tolerances, scheduler."""
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
        "--drift-front",
        action="store_true",
        help=(
            "also trace white-noise resolution against drift sensitivity (drift_front.json; "
            "slow), with each design's total error in --conditions"
        ),
    )
    p.add_argument(
        "--tolerances",
        metavar="FILE.toml",
        help=(
            "optimise robustly against these tolerances (the file of `tolerance --tolerances`): "
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


def run(args):
    """Optimise through :func:`~reflector_opt.workflow.optimise_run`, print a summary (or
    ``--json``); returns the exit code."""
    from reflector_opt.workflow import OptimiseOptions, optimise_run

    options = OptimiseOptions(
        config=args.config,
        seed=args.seed,
        surface=args.surface,
        sensor=args.sensor,
        starts=args.starts,
        workers=args.workers,
        pareto=args.pareto,
        tolerances=args.tolerances,
        scheduler=args.scheduler,
        report=not args.no_report,
        conditions=args.conditions,
        drift_front=args.drift_front,
    )
    result = call_into_folder(args, optimise_run, options)
    if result.robust is not None and not result.robust.converged:
        print(
            "reflector-opt optimise: warning: the robust margin did not converge in "
            f"{len(result.robust.rounds)} rounds; design.json keeps the last round "
            "(raise [robust] max_rounds)",
            file=sys.stderr,
        )
    if args.json:
        print_json(result.to_dict())
    else:
        print(format_run(result, args.started, args.tolerances))
    return 0


def format_run(result, started, tolerances=None):
    """The printed summary of an :class:`~reflector_opt.workflow.OptimiseRun`: the design,
    the sensor ranking, the predicted calibration, the robust rounds, the Pareto front, the
    parts and the files written (``started``: ``time.perf_counter()`` at the start, s;
    ``tolerances``: the file of ``--tolerances``, named with the yields)."""
    lines = [format_summary(result.result)]
    choice = result.design.predicted.get("sensor_choice")
    calibration = None if result.predicted is None else result.predicted["calibration"]
    if choice is not None:
        lines += result.ranking_lines() + ranking_basis(choice, calibration)
    if calibration is not None:
        lines += calibration_lines(calibration)
    if result.robust is not None:
        lines.append(format_robust(result.robust, tolerances))
    if result.front is not None:
        lines.append(format_pareto(result.front, tolerances))
    drift = result.design.predicted.get("drift_front")
    if drift is not None:
        lines += format_drift_front(drift)
    if result.cad is not None and result.cad.error is not None:
        lines.append(result.cad.summary())
    lines.append(folder_lines(result.out, result.files, started))
    return "\n".join(lines)


def ranking_basis(choice, calibration):
    """A line saying what the ranking's calibration RMS is computed on, against the
    prediction printed after it (more built units: a different figure of the same error)."""
    line = f"  the ranking's calibration RMS: {choice['calibration']}, seed {choice['seed']}"
    if calibration is not None:
        protocol = calibration["protocol"]
        line += (
            f"; the predicted calibration below: {protocol['n_units']} built units, seed "
            f"{protocol['seed']} (the same method on more units, so a figure of its own)"
        )
    return [line]


def format_robust(robust, tolerances=None):
    """Human-readable lines for a :class:`~reflector_opt.optimise.robust.RobustResult`
    (``tolerances``: the file they came from, for the label)."""
    coverage = f"{100 * robust.options.coverage:g} %"
    verdict = "covered" if robust.converged else "NOT covered"
    samples = robust.tolerance.run.samples
    basis = (
        f"95 % upper bound from {samples} sampled units"
        if robust.rounds[-1]["required_confidence"] is not None
        else f"sample quantile of {samples} units, too few for a 95 % bound"
    )
    source = "built-in" if tolerances is None else tolerances
    lines = [
        f"robust margin (the loss in {coverage} of built units, {basis}, seed "
        f"{robust.tolerance.run.seed}, tolerances {source}; its yield counts the distance "
        f"window only): {verdict} after {len(robust.rounds)} round(s)",
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


def format_pareto(front, tolerances=None):
    """The Pareto front as a table, with the yield of each point once estimated and what it
    counts (``tolerances``: their file, for the label)."""
    from reflector_opt.workflow.tolerance_text import yield_basis

    with_yield = front.yield_basis is not None
    header = "  required (mm)  margin (mm)  pitch (°)  roll (°)"
    if with_yield:
        basis = front.yield_basis
        judged = "all targets" if basis["calibrated"] else "distance window"
        label = yield_basis(basis["samples"], basis["seed"], tolerances, judged)
        header += f"  yield ({label}) [95 % interval]"
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


def format_drift_front(front):
    """The drift front (``predicted["drift_front"]``) as a table."""
    total = front["conditions"] is not None
    header = "  drift limit (°)  drift (°/1 %)  objective (°)  pitch (°)  roll (°)"
    lines = [f"drift front (seed {front['seed']}; white-noise objective against common drift):"]
    lines.append(header + ("  total in the conditions (°)" if total else ""))
    points = list(front["points"])
    if front["reference"] is not None:
        points.append({**front["reference"], "drift_limit_deg": "conditions"})
    for p in points:
        limit = p["drift_limit_deg"]
        label = "none" if limit is None else limit if isinstance(limit, str) else f"{limit:.3f}"
        if not p["feasible"]:
            lines.append(f"  {label:>15}  no design: {p['reason']}")
            continue
        row = (
            f"  {label:>15}  {p['drift_deg']:>13.3f}  {p['objective_deg']:>13.4f}  "
            f"{p['worst_pitch_deg']:>9.4f}  {p['worst_roll_deg']:>8.4f}"
        )
        if total:
            row += f"  {p['worst_case_deg']:>27.3f}"
        if p.get("kept_from"):
            row += f"  (the design of {p['kept_from']})"
        lines.append(row + ("  (dominated)" if p["dominated"] else ""))
    return lines


def format_conditions(block):
    """The worst-case total error in the conditions (``predicted["conditions"]``), the sources
    that bind and the default design's figure."""
    c, binding = block["conditions"], block["binding"]
    lines = [
        f"  worst-case total error in the conditions (±{c['temperature_range_k']:g} K, "
        f"{c['drive']} drive; form misfit left out): {block['worst_case_deg']:.4f}° "
        f"(pitch {block['worst_pitch_deg']:.4f}°, roll {block['worst_roll_deg']:.4f}°)"
    ]
    if "baseline" in block:
        lines.append(
            f"  default design in the same conditions: {block['baseline']['worst_case_deg']:.4f}°;"
            f" improvement {block['improvement']:.2f}×"
        )
    sources = ", ".join(
        f"{name} {e:.3f}° ({100 * block['binding']['shares'][name]:.0f} %)"
        for name, e in binding["sources_deg"].items()
    )
    pitch, roll = binding["pose_deg"]
    lines.append(f"  at its worst ({binding['angle']} at {pitch:g}°, {roll:g}°): {sources}")
    return lines


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
    if "conditions" in p:
        lines += format_conditions(p["conditions"])
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
