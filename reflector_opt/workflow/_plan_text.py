"""The text ``reflector-opt plan-calibration`` prints: the table of a calibration plan's
predictions and its recommendation (with the temperature study), or the tables of a plan for
identification; each from the plan's summary (``plan.json``'s content)."""


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
        return lines + thermometer_lines(thermal.get("thermometer"))
    at = " and ".join(f"T0 {dt:+g} K" for dt in pick["changes_k"])
    worst = max(max(row) for row in pick["ratio"])
    lines.append(
        f"temperature: the plan at T0, then {pick['n_poses']} Sobol poses at {at} "
        f"(plan_temperature.csv; {worst:.2f}× their T0 error at worst, uncompensated "
        f"{max(max(row) for row in thermal['uncompensated_ratio']):.2f}×; motion "
        f"{pick['motion_time_s'] / 60:.1f} min)"
    )
    return lines + thermometer_lines(thermal.get("thermometer"))


def thermometer_lines(costs):
    """What the thermometer and the light path's curvature cost, and the recommended
    placement and protocol, as text lines ([] without them)."""
    if not costs:
        return []
    at = " and ".join(f"T0 {dt:+g} K" for dt in costs["changes_k"])
    curvature = "/".join(f"{k:.2g}" for k in costs["curvature_per_k2"])
    lines = [
        f"thermometer (what the compensation does not see; {costs['n_poses']} poses at {at}, "
        f"the parts' light path, curvature {curvature} /K², {costs['n_units']} built units): "
        "RMS over the same poses' at T0, worst ΔT and sign; without → with the remedy",
    ]
    for row in costs["rows"]:
        lines.append(
            f"  {row['imperfection']:<40}{row['ratio']:>6.2f}× → {row['protocol_ratio']:.2f}×  "
            f"{row['remedy']}"
        )
    protocol, worst = costs["protocol"], costs["rows"][-1]["protocol_ratio"]
    verdict = "within" if worst <= protocol["target"] else "NOT within"
    lines.append(
        f"thermometer: recommended a thermometer at each sensor on its copper "
        f"({protocol['lag_s']:g} s behind), logged with every reading at calibration and in "
        f"use; calibration data at T0 and {at}, taken once the reading changes by less than "
        f"{costs['settle_rate_k_per_min']:.2g} K/min; the compensation with a term in ΔT² "
        f"({worst:.2f}× at worst, {verdict} {protocol['target']:g}×); it needs the "
        f"thermometer's offset to change by less than {costs['allowed_error_k']:.2f} K from "
        "calibration to use, lag × rate included"
    )
    return lines


def _ratio_cells(ratio):
    return "".join(f"{max(row):>7.2f}" for row in ratio)


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
    lines = [
        f"recommended: {best['n_poses']} D-optimal poses bring the {len(best['determinable'])} "
        f"determinable parameters to the target; motion {best['motion_time_s'] / 60:.1f} min "
        f"at {best['speed_deg_s']:g}°/s with {best['dwell_s']:g} s per pose"
    ]
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
