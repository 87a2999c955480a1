"""The text ``reflector-opt tolerance`` and ``reflector-opt sweep`` print: a tolerance
study's summary (yield with its interval and basis, the error distributions, the required
margin, the Sobol indices) and a sweep's table, one line per point; and the label of what a
yield counts (:func:`yield_basis`), which ``optimise`` prints too."""

import math


def _percent(fraction):
    return "not assessed" if fraction is None else f"{100 * fraction:.1f} %"


def _dist(d, key):
    v = d[key]
    return (
        "n/a" if v is None else f"median {v['median']:.3f}, p95 {v['p95']:.3f}, max {v['max']:.3f}"
    )


def _index(value, ci):
    if value is None:
        return "n/a"
    low, high = ("?" if v is None else f"{v:.2f}" for v in ci)
    return f"{value:.2f} ({low} to {high})"


def format_sobol(sobol):
    """Lines of a table of the Sobol indices (ranked by total index) with their intervals."""
    head = (
        f"  Sobol indices of the worse RMS error ({sobol['rows']} rows of "
        f"{sobol['rows_requested']}; {100 * sobol['confidence']:g} % bootstrap intervals)"
    )
    if sobol["dropped"] or sobol["unused"]:
        head += (
            f"; {sobol['dropped']} rows left out with a unit not built or calibrated, "
            f"{sobol['unused']} to keep a power of two"
        )
    if "error" in sobol:
        return [head, f"    not computed: {sobol['error']}"]
    ranked = sorted(
        sobol["groups"], key=lambda g: -(g["total"] if g["total"] is not None else -math.inf)
    )
    width = max(len(g["tolerance"]) for g in ranked)
    lines = [head, f"    {'tolerance':<{width}}  {'total index':<22}first-order index"]
    lines += [
        f"    {g['tolerance']:<{width}}  {_index(g['total'], g['total_ci']):<22}"
        f"{_index(g['first'], g['first_ci'])}"
        for g in ranked
    ]
    lines += [
        f"  WARNING: the {'first-order' if o['index'] == 'first' else 'total'} index of "
        f"{o['tolerance']}, {_index(o['value'], o['ci'])}, lies outside [0, 1] beyond its "
        "interval: sampling scatter does not explain it; check the model runs"
        for o in sobol["outside"]
    ]
    lines += [f"  note: bootstrap of the Sobol indices: {w}" for w in sobol["warnings"]]
    return lines


def yield_basis(samples, seed, tolerances, judged="all targets"):
    """What a yield is computed on, for its label: ``500 units, seed 0, tolerances FILE
    (built-in without one), all targets``.

    ``tolerance``, ``sweep`` and ``optimise --tolerances`` draw their units from the tolerance
    file they are given with their own sample counts and seeds, so one design's yield differs
    between them; each names its basis with this label.
    """
    source = "built-in" if tolerances is None else str(tolerances)
    return f"{samples} units, seed {seed}, tolerances {source}, {judged}"


def format_summary(study, tolerances=None):
    """Human-readable lines for a :class:`~reflector_opt.tolerance.ToleranceStudy`
    (``tolerances``: the file its tolerances came from, None for the built-in ones)."""
    s = study.summary
    y, t, d = s["yield"], s["targets"], s["distributions"]
    low, high = s["yield_interval"]["all"]
    lines = [
        f"{s['samples']} units (seed {study.seed}, tolerances "
        f"{'built-in' if tolerances is None else tolerances}; {s['invalid']} invalid, "
        f"{s['unfit']} not calibratable): yield "
        f"{100 * y['all']:.1f} % (95 % interval {100 * low:.1f}–{100 * high:.1f} %; "
        f"window kept {100 * y['window']:.1f} %, "
        f"RMS ≤ {t['rms_deg']:g}° {_percent(y['rms'])}, max ≤ {t['max_deg']:g}° "
        f"{_percent(y['max'])})",
    ]
    for key, label in (
        ("rms_pitch_deg", "RMS pitch error (°)"),
        ("rms_roll_deg", "RMS roll error (°)"),
        ("max_pitch_deg", "max pitch error (°)"),
        ("max_roll_deg", "max roll error (°)"),
        ("distance_margin_mm", "distance margin (mm)"),
    ):
        lines.append(f"  {label}: {_dist(d, key)}")
    if "required_margin_mm" in s:
        m = s["required_margin_mm"]
        bound = (
            f"{100 * m['confidence']:g} % upper bound; estimate {m['estimate']:.3f} mm"
            if m["confidence"] is not None
            else "estimate; too few samples for a confidence bound"
        )
        lines.append(
            f"  margin lost to the tolerances in {100 * m['coverage']:g} % of units: "
            f"{m['value']:.3f} mm ({bound}; optimise --tolerances sets it as the distance "
            "margin)"
        )
    if study.sobol:
        lines += format_sobol(study.sobol)
    return "\n".join(lines)


def _num(value, digits=3):
    return "n/a" if value != value else f"{value:.{digits}f}"


def format_table(rows, paths, basis=None):
    """One line per sweep point: the in-use worst-case error the optimiser minimises first
    (where the rows have it), then the white-noise resolution, the distance window, the
    nominal calibrated RMS error and the yield (``basis``: what it counts,
    :func:`yield_basis`)."""
    lines = []
    for row in rows:
        point = ", ".join(f"{p}={row[p]:g}" for p in paths)
        if row["status"] != "ok":
            lines.append(f"{point}: {row['status']}")
            continue
        worst = row.get("nominal_worst_case_deg")
        text = f"{point}: " + ("" if worst is None else f"in-use worst case {_num(worst)}°, ")
        text += (
            f"white-noise worst 1σ pitch/roll {_num(row['nominal_resolution_pitch_deg'])}"
            f"/{_num(row['nominal_resolution_roll_deg'])}°, window "
            f"{'kept' if row['nominal_window_kept'] else 'LOST'} "
            f"(margin {_num(row['nominal_distance_margin_mm'])} mm), RMS pitch/roll "
            f"{_num(row['nominal_rms_pitch_deg'])}/{_num(row['nominal_rms_roll_deg'])}°"
        )
        if "yield" in row:
            text += f", yield {100 * row['yield']:.1f} %"
            text += "" if basis is None else f" ({basis})"
        lines.append(text)
    return "\n".join(lines)
