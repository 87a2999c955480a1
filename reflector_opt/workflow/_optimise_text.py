"""The text ``reflector-opt optimise`` prints of its run: the optimised design against the
default one (in the operating conditions, if any), the sensor parts' ranking, the predicted
calibration, the robust rounds, the Pareto front and the drift front."""

import math

from msgspec import UNSET

from reflector_opt.report._in_use import in_use_lines
from reflector_opt.report._ranking import RANKING_HEADER, ranking_rows
from reflector_opt.workflow._evaluate_text import calibration_lines
from reflector_opt.workflow._tolerance_text import yield_basis


def format_run(run):
    """The text ``optimise`` prints of an :class:`~reflector_opt.workflow.OptimiseRun`: the
    design, the sensor ranking, the predicted calibration, the robust rounds, the Pareto
    front, the drift front and why no parts were written (the files written and the wall
    time are the command's to print after it)."""
    lines = [format_summary(run.result)]
    choice = run.design.predicted.sensor_choice
    calibration = None if run.predicted is None else run.predicted.calibration
    if choice:
        lines += run.ranking_lines() + ranking_basis(choice, calibration)
    if calibration is not None:
        lines += calibration_lines(calibration)
    if run.robust is not None:
        lines.append(format_robust(run.robust, run.tolerances))
    if run.front is not None:
        lines.append(format_pareto(run.front, run.tolerances))
    drift = run.design.predicted.drift_front
    if drift:
        lines += format_drift_front(drift)
    if run.cad is not None and run.cad.error is not None:
        lines.append(run.cad.summary())
    return "\n".join(lines)


def ranking_lines(record):
    """The ranking of a :class:`~reflector_opt.optimiser._sensor_choice.SensorChoice` record
    as a text table.

    Parameters
    ----------
    record : dict
        ``predicted["sensor_choice"]`` of a design.

    Returns
    -------
    list of str
    """
    lines = [f"sensor parts ranked (seed {record['seed']}; {record['criteria']}):"]
    table = [RANKING_HEADER, *ranking_rows(record)]
    widths = [max(len(r[k]) for r in table if r[0] != "-" or k < 2) for k in range(len(table[0]))]
    for row in table:
        if row[0] == "-":
            lines.append(f"  {row[0]:>{widths[0]}}  {row[1]:<{widths[1]}}  {row[2]}")
        else:
            cells = [f"{row[0]:>{widths[0]}}", f"{row[1]:<{widths[1]}}", f"{row[2]:<{widths[2]}}"]
            cells += [f"{c:>{w}}" for c, w in zip(row[3:], widths[3:], strict=True)]
            lines.append("  " + "  ".join(cells))
    lines.append(f"  chosen: {record['chosen']} ({record['part']['datasheet']})")
    return lines


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
    """Human-readable lines for a :class:`~reflector_opt.optimiser._robust.RobustResult`
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
    """The Pareto front as a table: each point's white-noise floor (worst 1σ pitch and roll),
    its in-use worst case where the front was traced in conditions, and the yield of each
    point once estimated with what it counts (``tolerances``: their file, for the label)."""
    with_yield = front.yield_basis is not None
    in_use = any(math.isfinite(p.worst_case_deg) for p in front.points)
    header = "  required (mm)  margin (mm)  pitch (°)  roll (°)" + "  in use (°)" * in_use
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
        row += f"  {p.worst_case_deg:>10.4f}" * in_use
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


def format_conditions(block, floor_deg=None):
    """The error in use (``predicted.conditions``) as every command words it
    (:func:`~reflector_opt.report._in_use.in_use_lines`, the white-noise floor ``floor_deg``),
    with the read-out chosen after its first line and what the read-out alone buys the default
    design after the default design's."""
    lines = in_use_lines(block, floor_deg)
    read_out = {} if block.read_out is UNSET else block.read_out
    if read_out:
        lines.insert(1, _read_out_line(read_out))
    at = 2 if block.baseline is UNSET else 3
    default = read_out.get("default_design")
    if default is not None:
        compensated = ", compensated" if default["temperature_compensated"] else ""
        lines.insert(
            at,
            f"  default design in the read-out chosen for it ({default['drive']} at "
            f"{default['sample_rate_hz']:g} Sa/s{compensated}): worst case "
            f"{default['worst_case_deg']:.4f}°, median {default['median_deg']:.4f}°",
        )
    elif block.baseline_read_out is not UNSET and not _stated_kept(read_out):
        lines.insert(
            at,
            "  default design in the chosen read-out: worst case "
            f"{block.baseline_read_out['worst_case_deg']:.4f}° (what the read-out alone buys)",
        )
    return lines


def _read_out_line(read_out):
    """The read-out chosen, what it costs and the stated one it replaced."""
    chosen, stated = read_out["chosen"], read_out["stated"]
    thermometer = "a thermometer, " if chosen["temperature_compensated"] else ""
    kept = "the stated one" if _stated_kept(read_out) else f"stated: {stated['drive']}"
    line = (
        f"  read-out chosen ({kept}; the simplest within {100 * read_out['worth']:g} % of the "
        f"best of {len(read_out['candidates'])}): {chosen['drive']} at "
        f"{chosen['sample_rate_hz']:g} Sa/s, {thermometer}{chosen['frame_rate_hz']:.0f} "
        "frames/s"
    )
    searched = read_out.get("searched_in")
    if searched is not None:
        line += f"; geometry searched in {searched['drive']} at {searched['sample_rate_hz']:g} Sa/s"
    if read_out.get("missed"):
        line += f" (in the default design's read-out: {read_out['missed']})"
    return line


def _stated_kept(read_out):
    return all(read_out["chosen"][key] == value for key, value in read_out["stated"].items())


def resolution_text(value):
    """A worst-case resolution, degrees to four decimals with ``°``; ``inf`` for None (a
    design with no sensitivity there)."""
    return "inf" if value is None else f"{value:.4f}°"


def _slack(record):
    return "∞" if record["margin"] is None else f"{record['margin']:.1f}"


def format_summary(result):
    """The design part of ``optimise``'s text for an
    :class:`~reflector_opt.optimiser.OptimisationResult`: the error in use first where it was
    optimised in conditions, then reflector, sensors, resolution against the default design
    and the constraints' slack."""
    p = result.design.predicted
    m = p.metrics
    r = m["resolution_deg"]
    refl = result.design.reflector
    lines = [
        f"optimised design (seed {result.seed}, "
        f"{sum(result.evaluations.values())} model evaluations)",
    ]
    if p.conditions:
        worst = [v for v in (r["pitch_worst"], r["roll_worst"]) if v is not None]
        lines += format_conditions(p.conditions, max(worst) if worst else None)
    lines += [
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
        f"{resolution_text(r['pitch_worst'])}, roll {resolution_text(r['roll_worst'])} "
        f"(σ_V = {m['sigma_v'] * 1e3:.2f} mV)"
    )
    windows = ", ".join(
        f"{lo:.3f}–{hi:.3f} mm"
        for lo, hi in zip(m["distance_mm"]["min"], m["distance_mm"]["max"], strict=True)
    )
    lines.append(f"  distance windows: {windows}")
    if p.baseline:
        b = p.baseline["metrics"]["resolution_deg"]
        imp = p.improvement.get("resolution", p.improvement)
        factor = "n/a" if imp["worst"] is None else f"{imp['worst']:.2f}×"
        lines.append(
            f"  default design: pitch {resolution_text(b['pitch_worst'])}, "
            f"roll {resolution_text(b['roll_worst'])}; white-noise improvement {factor}"
        )
    c = p.constraints
    lines.append(
        "  constraints met on the workspace grid; slack (how far inside each limit): "
        f"distance margin {c['distance_margin_mm']['margin']:.3f} mm, "
        f"wall {c['wall_mm']['margin']:.3f} mm, "
        f"sensor envelope {c['sensor_envelope_mm']['margin']:.3f} mm, "
        f"reflector envelope {c['reflector_envelope_mm']['margin']:.3f} mm, "
        f"uniqueness {_slack(c['separation_sigma'])} σ_V"
    )
    return "\n".join(lines)
