"""The text ``reflector-opt evaluate`` prints: the figures in use first
(:func:`~reflector_opt.report._conditions.in_use_lines`, as ``optimise`` prints them), then a
design's distance and voltage ranges, its surface, its drift sensitivity, the error budget in
its conditions, the predicted calibration (with a warning where a paper's form is far from the
Cramér–Rao floor) and the predicted segment errors beside the paper's;
:func:`calibration_lines` is printed by ``optimise`` too."""

from reflector_opt.report._in_use import in_use_lines


def format_summary(summary):
    """The text ``evaluate`` prints of an
    :class:`~reflector_opt.tolerance._prediction.Evaluation`."""
    lines = in_use_lines(summary.in_use)
    lines = [lines[0].lstrip(), *lines[1:], f"workspace: {summary.workspace['poses']} poses"]
    for s in summary.sensors:
        d, v = s.distance_mm, s.volts
        lines.append(
            f"{s.name} ({s.model}): d {d.min:.3f}–{d.max:.3f} mm (usable {s.range_mm[0]}–"
            f"{s.range_mm[1]} mm: {'inside' if s.in_range else 'OUTSIDE'}), "
            f"V {v.min:.3f}–{v.max:.3f} V"
        )
    lines.append(f"design {'stays inside' if summary.in_range else 'leaves'} the sensor range")
    lines += _surface_lines(summary.surface)
    lines += drift_lines(summary.drift_sensitivity)
    if summary.budget:
        lines += budget_lines(summary)
    if summary.calibration:
        lines += calibration_lines(summary.calibration)
    for segment in (summary.segment, summary.segment_recommended):
        if segment:
            lines += _segment_lines(segment)
    return "\n".join(lines)


def drift_lines(drift):
    """Text lines of a ``drift_sensitivity`` block: angle error per 1 % light-path change."""
    lines = ["drift sensitivity, angle error per 1 % change of the light path (pitch / roll):"]
    for name, e in drift.items():
        lines.append(
            f"  {name:>8}: RMS {e['pitch_rms_deg']:.3f}° / {e['roll_rms_deg']:.3f}°, "
            f"max {e['pitch_max_deg']:.3f}° / {e['roll_max_deg']:.3f}°"
        )
    return lines


def settling_lines(drive):
    """The text line of a switched drive's settling: the residue and the rate that settles."""
    if drive["scheme"] == "dc" or drive.get("settling_rate_hz") is None:
        return []
    return [
        f"detectors under {drive['scheme']} drive: each reading keeps "
        f"{100 * drive['settled_share']:.1f} % of its own LED's light (ambient light, dark "
        f"current and noise weigh {1 / drive['settled_share']:.2f}× more) and carries "
        f"{100 * drive['settling_residue']:.1f} % of the light lit before it (crosstalk left "
        f"that share); they settle to 0.1 % at {drive['settling_rate_hz']:.0f} conversions/s "
        "or fewer"
    ]


def joint_lines(joint):
    """The text line of a budget's ``joint`` block: what of the clearance stays."""
    stays = joint["stays_um"]
    if not joint["seated"]:
        return [
            f"joint: clearance {joint['clearance_um']:g} µm, free or its load reversing: "
            f"±{stays[0]:.1f} µm on every axis stays"
        ]
    return [
        f"joint: clearance {joint['clearance_um']:g} µm, seated by the tendons' preload: "
        f"{joint['learned_um']:.1f} µm along the load learned by the calibration, "
        f"±{stays[0]:.1f} µm across it stays (the friction cone)"
    ]


def assumed_lines(assumed):
    """The text line naming the assumed figures a budget leans on (--json has each source)."""
    if not assumed:
        return []
    names = ", ".join(f["figure"] for f in assumed)
    return [f"leans on {len(assumed)} assumed figure(s) (--json gives each source): {names}"]


def budget_lines(summary):
    """Text lines of the error budget in the summary's conditions."""
    c, drive = summary.conditions, summary.drive
    heating = ", ".join(f"{k:.2f}" for k in drive["self_heating_k"])
    lines = [
        f"error budget in use (±{c['temperature_range_k']:g} K, ambient {c['ambient_mv']:g} mV, "
        f"{c['drive']} drive: {drive['frame_rate_hz']:g} frames/s, LED self-heating "
        f"{heating} K; RMS root-sum-square, max summed):",
        "    source          pitch RMS   roll RMS   pitch max   roll max",
    ]
    for name, e in summary.budget.items():
        lines.append(
            f"  {name:<14} {e['pitch_rms_deg']:9.3f}° {e['roll_rms_deg']:9.3f}° "
            f"{e['pitch_max_deg']:10.3f}° {e['roll_max_deg']:9.3f}°"
        )
    lines.append(
        f"worst case in use with the recommended form's misfit in: {summary.worst_case_deg:.3f}°"
    )
    lines += settling_lines(drive)
    lines += joint_lines(summary.joint) + assumed_lines(summary.assumed_figures)
    lines.append("the drive schemes in the same conditions (total RMS pitch / roll, worst case):")
    for scheme, row in summary.drive_comparison.items():
        lines.append(
            f"  {scheme:<12} {row['pitch_rms_deg']:.3f}° / {row['roll_rms_deg']:.3f}°, "
            f"worst {row['worst_case_deg']:.3f}°, {row['frame_rate_hz']:g} frames/s"
        )
    return lines


def _surface_lines(surface):
    sweep = surface["resolution_against_specular_fraction"]
    lines = [
        f"surface: reflectance {surface['reflectance']}, specular fraction "
        f"{surface['specular_fraction']} (the rest Lambertian)",
        "worst-case 1σ resolution against the specular fraction f (pitch / roll, degrees):",
        "     f   this design        default design",
    ]
    for mine, base in zip(sweep["design"], sweep["default_design"], strict=True):
        lines.append(
            f"  {mine['specular_fraction']:4.2f}   {mine['worst_pitch_deg']:.4f} / "
            f"{mine['worst_roll_deg']:.4f}   {base['worst_pitch_deg']:.4f} / "
            f"{base['worst_roll_deg']:.4f}"
        )
    return lines


def calibration_lines(calibration):
    """Text lines of a :class:`~reflector_opt.tolerance._prediction.CalibrationPrediction`."""
    protocol, floor = calibration.protocol, calibration.floor_rms_deg
    lines = [
        f"predicted calibration of {protocol['n_units']} built units (exact optics, "
        f"reference noise {protocol['reference_sigma_deg']:g}°, {protocol['n_validation']} "
        "validation poses each; error = estimate − truth, % = RMS / span):",
        f"  Cramér–Rao floor: RMS pitch {floor.pitch:.3f}° roll {floor.roll:.3f}°",
    ]
    for name in ("eq5", "eq6", "recommended"):
        block = getattr(calibration, name)
        if name == "recommended":
            ratio = block.floor_ratio
            label = (
                f"recommended ({'/'.join(sorted(set(block.models)))} chosen by "
                f"cross-validation, {block.n_calibration}-pose {block.plan['pattern']}; "
                f"{ratio.pitch:.2f}× / {ratio.roll:.2f}× the floor)"
            )
        else:
            label = f"{name} ({block.n_calibration}-pose raster at {protocol['step_deg']:g}°)"
        rms, peak, pct = block.rms_deg, block.max_deg, block.percent_error
        misfit, noise = block.misfit_rms_deg, block.noise_rms_deg
        lines.append(
            f"  {label}: RMS pitch {rms.pitch:.3f}° roll {rms.roll:.3f}°, "
            f"max {peak.pitch:.3f}° / {peak.roll:.3f}°, {pct.pitch:.2f} % / {pct.roll:.2f} % "
            f"(model misfit {misfit.pitch:.3f}° / {misfit.roll:.3f}°, "
            f"noise {noise.pitch:.3f}° / {noise.roll:.3f}°)"
        )
    return lines + form_warnings(calibration)


#: A form whose predicted RMS error is more than this many times the Cramér–Rao floor in an
#: angle is far from it: its misfit, not the noise, sets the error.
FAR_FROM_FLOOR = 10.0


def form_warnings(calibration):
    """A warning line for each of the paper's forms (eq5, eq6) far from the floor.

    Parameters
    ----------
    calibration : reflector_opt.tolerance._prediction.CalibrationPrediction

    Returns
    -------
    list of str
        For a form whose RMS error exceeds :data:`FAR_FROM_FLOOR` times the Cramér–Rao floor
        in pitch or roll: its error, how far from the floor, what makes it (misfit or noise)
        and the form to use instead (the recommended one, with its error).
    """
    floor, best = calibration.floor_rms_deg, calibration.recommended
    instead = "/".join(sorted(set(best.models)))
    lines = []
    for name in ("eq5", "eq6"):
        block = getattr(calibration, name)
        axis = max(("pitch", "roll"), key=lambda a: block.rms_deg[a] / floor[a])
        ratio = block.rms_deg[axis] / floor[axis]
        if ratio <= FAR_FROM_FLOOR:
            continue
        cause = (
            "model misfit" if block.misfit_rms_deg[axis] > block.noise_rms_deg[axis] else "noise"
        )
        lines.append(
            f"  warning: {name} is {ratio:.0f}× the floor in {axis} ({block.rms_deg[axis]:.3f}° "
            f"RMS, {block.percent_error[axis]:.1f} % of the span; its {cause}): it cannot "
            f"follow this design's response; calibrate with {instead} instead "
            f"(`calibrate --model auto`: {best.rms_deg.pitch:.3f}° / "
            f"{best.rms_deg.roll:.3f}° predicted)"
        )
    return lines


def _segment_lines(segment):
    lines = [
        f"predicted segment tip error ({segment['n_units']} units, {segment['model']}), "
        "beside the paper's Table I (% = RMS / the tip angle's span; the paper's % is not "
        "RMS / span and it does not say what it is, so it does not compare):"
    ]
    for axis in ("pitch", "roll"):
        block = segment[axis]
        ours, paper = block["predicted"], block["paper"]
        lines.append(
            f"  {axis} ±{block['amplitude_deg']:g}°: RMS {ours['rms_deg']:.2f}° "
            f"(paper {paper['rms_deg']}°), max {ours['max_deg']:.2f}° "
            f"(paper {paper['max_deg']}°), {ours['percent_error']:.2f} % "
            f"(paper {paper['percent_error']} %, base not stated), "
            f"position RMS {ours['position_rms_mm']:.2f} mm"
        )
    return lines
