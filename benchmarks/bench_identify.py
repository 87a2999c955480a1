"""Benchmark: as-built identification scored on simulated built units with model-form error.

Run from the repository root:

    PYTHONPATH=. python benchmarks/bench_identify.py --units 50 --workers 2

Each unit is drawn by the tolerance model, built with the exact reference extended by the
model-form error (:class:`reflector_opt.tolerance._model_form.ModelForm` at its defaults), its
surface shared with the other units of its print batch (batches of five, ρ and f drawn per
batch), calibrated on a plan with the design's noise and a 0.05° angle reference, and
identified twice: from the calibration data alone and with both sensors' flat-target curves
(21 distances, 0.5–3 mm). The scores, against the unit's true geometry
(:func:`reflector_opt.asbuilt._parameters.true_deviations`):

* coverage — for each parameter called determinable, the share of units whose 90 % interval
  (the profile interval where there is one, else ±1.645 std) holds the truth (target 80–97 %);
  gains, offsets, beam width, source size and reflectance take up the model-form error and
  have no literal truth; they are listed apart, the offset's truth being the unit's offset
  plus the shift of its crosstalk and ambient light;
* the RMS error of each parameter called determinable, in prior std (≤ 0.7), and along each
  determined combination that is geometric (the reflector's radius and centre, the seats:
  at least 80 % of its squared weight) (≤ 0.5);
* the as-built distance of each sensor over the workspace (a 16 × 16 grid): RMS error within
  2.5× its reported std in ≥ 90 % of units; at least 2× closer than the design wherever the
  design is ≥ 50 µm off; within 15 µm RMS with the curves;
* the tilt towards the detector: its error where it is determined (≤ 0.5°);
* f: its interval holds the truth, or it is called not determinable;
* angles through the identified unit on 2,000 validation poses against the unit's
  Cramér–Rao floor (≤ 1.2×);
* CPU seconds per unit (the fit alone; and with its profile intervals and the model-form
  term, which costs a few seconds per batch, not per unit).

Prints the tables and writes the figures as JSON (``--out``). ``--identifiability N`` prints
instead the median posterior/prior std of every parameter over N units, from calibration
data alone and with curves, with and without the model-form term. ``--reference-zero``
``free`` (the default, as ``identify``'s) fits each unit's angle reference (its zero offsets
and twist, the data recorded by an exact one), ``fixed`` takes it as exact.

``--reference-errors N`` scores instead the identification when the reference is wrong, in a
way its prior does not describe: N units (model-form error as above), each recorded by a
reference whose pitch and roll zero offsets are drawn uniform in ±2° and its twist uniform in
±1° (the prior: normal, 1.5°, 1.5°, 0.5°), from 200 Sobol poses, identified from calibration
data alone (normal 90 % intervals, ±1.645 std, with the model-form term). The same voltages
are identified once more with the readings of an exact reference, and once more with the
erring readings but the reference taken as exact (``--reference-zero fixed``, on the poses
whose readings stay within 1° of the workspace, as that mode requires). Scores: the
coverage of the 90 % intervals of the reference's parameters and of every geometric one
(determined or not); how far each geometric estimate moves from the exact reference's fit,
in its std (target ≤ 1); the same for the fit that takes the erring reference as exact.

``--misspecified N`` scores the identification (its defaults: spread, emitters, model-form
amplitudes and reference fitted) on truths its prior does not know, N units per case:
``control`` (the tolerance model's deviations, ``ModelForm()``), ``tolerances_2x`` (every
print and read-out tolerance doubled), ``spread`` (sub-surface spread drawn uniform in
0.15–0.3 mm), ``emitters`` (sensor 1 a two-Gaussian LED 3° wider and 40 µm larger than the
model's, sensor 2 a cosine-power LED 2.5° narrower and 20 µm smaller) and ``reference``
(zero offsets uniform in ±2°, twist in ±1°; each unit also identified from the exact
readings, the geometry's move in its std). Per case and geometric parameter: the coverage
of the 90 % intervals (±1.645 std) of the units in which it is called determined, and of
all units. From calibration data alone and with both sensors' flat-target curves.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import fields, replace

import numpy as np

from reflector_opt.asbuilt._identification import identify
from reflector_opt.asbuilt._parameters import SUBSURFACE_NOMINAL_MM, true_deviations
from reflector_opt.asbuilt._problem import Curve
from reflector_opt.calibration._plans import make_plan
from reflector_opt.design import default_design
from reflector_opt.model._geometry import sensor_distance
from reflector_opt.tolerance._builtunit import build_unit, built_unit_protocol, crlb_floor_deg
from reflector_opt.tolerance._model_form import ModelForm
from reflector_opt.tolerance._tolerances import Spread, Tolerances
from reflector_opt.util._errors import FitError
from reflector_opt.util._seeds import stream_rng

BATCH = 5
#: Children of a unit's seed streams (util.seeds) for the benchmark's own draws of the unit:
#: its flat-target curves and its angle reference's zero and twist (``"built_protocol"``:
#: measurements of the unit), its misspecified physics (``"tolerance_draw"``: how it is built).
FLAT_CURVES, REFERENCE, MISSPECIFIED = 1, 2, 1
CURVE_MM = np.linspace(0.5, 3.0, 21)
GRID = np.meshgrid(np.linspace(-15, 15, 16), np.linspace(-15, 15, 16))
EFFECTIVE = ("gain", "offset_v", "divergence_deg", "source_radius_mm", "reflectance")
NOT_GEOMETRY = ("offset_v", "divergence_deg", "source_radius_mm")
#: Geometry parameters (name endings); a combination counts as geometric when they carry at
#: least 80 % of its squared weight.
GEOMETRY = ("_mm", "_deg")


def batch_surface(seed, batch):
    """The print batch's shared (reflectance, specular fraction)."""
    rng = stream_rng(seed, "batch_surface", batch)
    return (
        float(np.clip(0.9 + 0.02 * rng.standard_normal(), 0.5, 1.0)),
        float(np.clip(0.05 + 0.02 * rng.standard_normal(), 0.0, 1.0)),
    )


def truth_vector(design, unit, reference=None):
    """The unit's true parameter vector; the offsets carry crosstalk and ambient light; with
    ``reference`` (pitch zero, roll zero, twist) its reference's errors after the block."""
    block = true_deviations(design, unit.design, unit.mismatch)
    reflector = unit.design.reflector
    n_reflector, per_sensor = 4, (len(block) - 4) // len(design.sensors)
    for k, model in enumerate(unit.design.models):
        shift = model.output_voltage(unit.model_form.extra_coupling(model)) - model.supply_v
        block[n_reflector + per_sensor * k + 6] += unit.mismatch.gain[k] * shift
    return np.r_[
        reflector.reflectance - design.reflector.reflectance,
        reflector.specular_fraction - design.reflector.specular_fraction,
        block,
        () if reference is None else reference,
    ]


def interval(result, j, name):
    """90 % interval of parameter j as a deviation: the profile's, else ±1.645 std."""
    profile = result.profiles.get(name)
    offset = result.layout.nominal()[j]
    if profile is not None:
        return profile.low - offset, profile.high - offset
    return result.x[j] - 1.645 * result.std[j], result.x[j] + 1.645 * result.std[j]


def score(design, unit, result, truth):
    """Per-parameter hits and errors, combinations' errors and distances of one fit."""
    prior = result.layout.prior_std()
    names = result.layout.names(list(result.labels))
    rows = {}
    for j, name in enumerate(names):
        ratio = result.std[j] / prior[j]
        low, high = interval(result, j, name)
        rows[name.split(": ")[-1]] = {
            "determined": bool(ratio <= 0.5),
            "hit": bool(low <= truth[j] <= high),
            "error_prior": float((result.x[j] - truth[j]) / prior[j]),
            "error": float(result.x[j] - truth[j]),
        }
    index = result.layout.unit_indices(0)
    scaled = ((result.x - truth) / prior)[index]
    combos = []
    local = [names[i] for i in index]
    kinds = [n.split(": ")[-1] for n in local]
    geometric = np.array([k.endswith(GEOMETRY) and not k.endswith(NOT_GEOMETRY) for k in kinds])
    for c in result.combinations[0]:
        vector = np.array([c.weights.get(n, 0.0) for n in local])
        if np.sum(vector[geometric] ** 2) >= 0.8 * np.sum(vector**2):
            combos.append(float(vector @ scaled / np.linalg.norm(vector)))
    built = unit.design
    true = sensor_distance(
        built.positions_mm, built.reflector.centre_mm, built.reflector.radius_mm, *GRID
    )
    nominal = sensor_distance(
        design.positions_mm, design.reflector.centre_mm, design.reflector.radius_mm, *GRID
    )
    found, std = result.distance_mm(0, *GRID)
    distance = [
        {
            "error_um": 1e3 * float(np.sqrt(np.mean((found - true)[..., k] ** 2))),
            "std_um": 1e3 * float(np.sqrt(np.mean(std[..., k] ** 2))),
            "nominal_um": 1e3 * float(np.sqrt(np.mean((nominal - true)[..., k] ** 2))),
        }
        for k in range(len(design.sensors))
    ]
    return {"rows": rows, "combinations": combos, "distance": distance}


def run_unit(args):
    """Build, calibrate and identify one unit (with and without curves): its scores."""
    index, seed, n_poses, n_validation, free = args
    options = {} if free else {"reference_std": None}
    design = default_design()
    plan = make_plan(design.workspace, "sobol", n_poses, seed=0)
    surface = batch_surface(seed, index // BATCH)
    unit = build_unit(design, index, seed=seed, model_form=ModelForm(), surface=surface)
    protocol = built_unit_protocol(unit, plan, n_validation=n_validation, seed=seed)
    rng = stream_rng(seed, "built_protocol", index, FLAT_CURVES)
    curves = [Curve(k, CURVE_MM, unit.flat_curve(k, CURVE_MM, rng)) for k in range(2)]
    data = {"u": (protocol.calibration.volts, protocol.calibration.angles_deg)}
    truth = truth_vector(design, unit, (0.0, 0.0, 0.0) if free else None)
    out = {"index": index}
    start = time.process_time()
    identify(design, data, profiles=False, model_form=None, **options)
    out["cpu_s_fit"] = time.process_time() - start
    start = time.process_time()
    alone = identify(design, data, profiles=True, **options)
    out["cpu_s_full"] = time.process_time() - start
    with_curves = identify(design, data, curves={"u": curves}, profiles=True, **options)
    out["alone"] = score(design, unit, alone, truth)
    out["curves"] = score(design, unit, with_curves, truth)
    out["f_true"] = surface[1]
    out["f_alone"] = alone.shared_parameters()["specular_fraction"]
    validation = protocol.validation
    error = alone.estimator(0).predict(validation.volts) - validation.angles_deg
    floor = crlb_floor_deg(unit, validation.angles_deg)
    out["angle_ratio"] = (np.sqrt(np.mean(error**2, axis=0)) / floor).tolist()
    return out


def summarise(results, key):
    """The benchmark's figures for one kind of fit (``alone`` or ``curves``)."""
    names = list(results[0][key]["rows"])
    table = {}
    for name in names:
        rows = [r[key]["rows"][name] for r in results]
        called = [row for row in rows if row["determined"]]
        table[name] = {
            "determined_units": len(called),
            "coverage_90": float(np.mean([row["hit"] for row in called])) if called else None,
            "rms_error_prior": (
                float(np.sqrt(np.mean([row["error_prior"] ** 2 for row in called])))
                if called
                else None
            ),
            "effective": name.endswith(EFFECTIVE),
        }
    distances = [d for r in results for d in r[key]["distance"]]
    far = [d for d in distances if d["nominal_um"] >= 50]
    per_unit_ok = [
        all(d["error_um"] <= 2.5 * d["std_um"] for d in r[key]["distance"]) for r in results
    ]
    combos = [c for r in results for c in r[key]["combinations"]]
    tilts = [
        abs(r[key]["rows"][f"sensor_{k}_tilt_led_detector_deg"]["error"])
        for r in results
        for k in (1, 2)
        if r[key]["rows"][f"sensor_{k}_tilt_led_detector_deg"]["determined"]
    ]
    return {
        "parameters": table,
        "distance_within_2_5_std_share": float(np.mean(per_unit_ok)),
        "distance_rms_um": float(np.sqrt(np.mean([d["error_um"] ** 2 for d in distances]))),
        "distance_2x_better_share": (
            float(np.mean([d["error_um"] <= d["nominal_um"] / 2 for d in far])) if far else None
        ),
        "nominal_50um_off_cases": len(far),
        "geometry_combination_rms_prior": (
            float(np.sqrt(np.mean(np.square(combos)))) if combos else None
        ),
        "geometry_combinations": len(combos),
        "tilt_determined_cases": len(tilts),
        "tilt_max_error_deg": float(max(tilts)) if tilts else None,
    }


def print_summary(label, summary):
    print(f"\n== {label}")
    print(f"{'parameter':<34}{'determined':>11}{'coverage':>10}{'RMS err/prior':>15}")
    for name, row in summary["parameters"].items():
        if not row["determined_units"]:
            continue
        mark = " (effective)" if row["effective"] else ""
        print(
            f"{name:<34}{row['determined_units']:>11}{row['coverage_90']:>10.2f}"
            f"{row['rms_error_prior']:>15.2f}{mark}"
        )
    for key in (
        "distance_within_2_5_std_share",
        "distance_rms_um",
        "distance_2x_better_share",
        "nominal_50um_off_cases",
        "geometry_combination_rms_prior",
        "geometry_combinations",
        "tilt_determined_cases",
        "tilt_max_error_deg",
    ):
        value = summary[key]
        print(f"{key:<40}{value if value is None else round(value, 3)}")


def identifiability_table(n_units, seed, free=True):
    """Median posterior/prior std per parameter, by the data and the model-form term used."""
    design = default_design()
    plan = make_plan(design.workspace, "sobol", 200, seed=0)
    cases = {
        "calibration": (False, None),
        "+ model form": (False, ModelForm()),
        "+ curves": (True, None),
        "+ curves + model form": (True, ModelForm()),
    }
    ratios = {case: [] for case in cases}
    for index in range(n_units):
        unit = build_unit(design, index, seed=seed, model_form=ModelForm(), surface=(0.9, 0.05))
        protocol = built_unit_protocol(unit, plan, n_validation=1, seed=seed)
        rng = stream_rng(seed, "built_protocol", index, FLAT_CURVES)
        curves = {"u": [Curve(k, CURVE_MM, unit.flat_curve(k, CURVE_MM, rng)) for k in range(2)]}
        data = {"u": (protocol.calibration.volts, protocol.calibration.angles_deg)}
        for case, (with_curves, form) in cases.items():
            result = identify(
                design,
                data,
                curves=curves if with_curves else None,
                profiles=False,
                model_form=form,
                **({} if free else {"reference_std": None}),
            )
            ratios[case].append(result.std / result.layout.prior_std())
    names = [n.split(": ")[-1] for n in result.layout.names()]
    print("| parameter | " + " | ".join(cases) + " |")
    print("| --- |" + " --- |" * len(cases))
    for j, name in enumerate(names):
        cells = [f"{np.median([r[j] for r in ratios[case]]):.2f}" for case in cases]
        print(f"| `{name}` | " + " | ".join(cells) + " |")


#: Limits of the reference's errors drawn in ``--reference-errors``: zero offsets uniform in
#: ±2°, twist uniform in ±1° (not the prior's normal 1.5°, 1.5°, 0.5°).
ZERO_LIMIT_DEG, TWIST_LIMIT_DEG = 2.0, 1.0


def read_through(angles_deg, reference):
    """What a reference with errors (pitch zero, roll zero, twist) reads: (γ, α)·R(κ) + z."""
    kappa = np.deg2rad(reference[2])
    rotation = np.array([[np.cos(kappa), np.sin(kappa)], [-np.sin(kappa), np.cos(kappa)]])
    return angles_deg @ rotation + np.asarray(reference[:2])


def geometry_rows(result):
    """The geometric parameters' rows of unit 0 (the emitter's are nuisance)."""
    rows = result.unit_parameters(0)
    return {n: r for n, r in rows.items() if n.endswith(GEOMETRY) and not n.endswith(NOT_GEOMETRY)}


def distance_error_um(result, unit):
    """RMS error of the as-built distance over the grid and both sensors, µm."""
    built = unit.design
    true = sensor_distance(
        built.positions_mm, built.reflector.centre_mm, built.reflector.radius_mm, *GRID
    )
    found, _ = result.distance_mm(0, *GRID)
    return 1e3 * float(np.sqrt(np.mean((found - true) ** 2)))


def run_reference_unit(args):
    """One unit recorded by an erring reference: fits with the reference exact, erring and
    fitted, erring and taken as exact; their scores."""
    index, seed, n_poses, form = args
    design = default_design()
    plan = make_plan(design.workspace, "sobol", n_poses, seed=0)
    surface = batch_surface(seed, index // BATCH)
    unit = build_unit(
        design, index, seed=seed, model_form=ModelForm() if form else None, surface=surface
    )
    calibration = built_unit_protocol(unit, plan, n_validation=1, seed=seed).calibration
    rng = stream_rng(seed, "built_protocol", index, REFERENCE)
    reference = (
        *rng.uniform(-ZERO_LIMIT_DEG, ZERO_LIMIT_DEG, 2),
        rng.uniform(-TWIST_LIMIT_DEG, TWIST_LIMIT_DEG),
    )
    volts, exact_read = calibration.volts, calibration.angles_deg
    read = read_through(exact_read, reference)
    kept = np.all(np.abs(read) <= 16.0, axis=1)  # what the anchored fit accepts
    fits = {
        "exact": identify(design, {"u": (volts, exact_read)}, profiles=False),
        "free": identify(design, {"u": (volts, read)}, profiles=False),
        "anchored_exact": identify(
            design, {"u": (volts[kept], exact_read[kept])}, profiles=False, reference_std=None
        ),
        "anchored": identify(
            design, {"u": (volts[kept], read[kept])}, profiles=False, reference_std=None
        ),
    }
    truth = true_deviations(design, unit.design, unit.mismatch)
    names = list(fits["free"].unit_parameters(0))
    out = {"index": index, "reference": list(reference), "kept": int(kept.sum())}
    for key, base in (("free", "exact"), ("anchored", "anchored_exact")):
        rows, before = geometry_rows(fits[key]), geometry_rows(fits[base])
        out[key] = {
            name: {
                "move_std": (row["estimate"] - before[name]["estimate"]) / row["std"],
                "error_std": (row["estimate"] - row["design"] - truth[names.index(name)])
                / row["std"],
                "determined": row["identifiable"],
            }
            for name, row in rows.items()
        }
        out[key + "_distance_um"] = distance_error_um(fits[key], unit)
    out["exact_distance_um"] = distance_error_um(fits["exact"], unit)
    out["reference_rows"] = {
        name: {**row, "truth": value}
        for (name, row), value in zip(
            fits["free"].reference_parameters(0).items(), reference, strict=True
        )
    }
    return out


def summarise_reference(results):
    """Coverage and moves over the units of ``--reference-errors``."""
    out = {"reference": {}, "geometry": {}}
    for name in results[0]["reference_rows"]:
        rows = [r["reference_rows"][name] for r in results]
        z = np.array([(row["estimate"] - row["truth"]) / row["std"] for row in rows])
        out["reference"][name] = {
            "coverage_90": float(np.mean(np.abs(z) <= 1.645)),
            "determined_share": float(np.mean([row["identifiable"] for row in rows])),
            "median_std_deg": float(np.median([row["std"] for row in rows])),
            "correlated_with": max(
                {row["correlated_with"] for row in rows},
                key=[row["correlated_with"] for row in rows].count,
            ),
        }
    for name in results[0]["free"]:
        entry = {}
        for key in ("free", "anchored"):
            moves = np.array([abs(r[key][name]["move_std"]) for r in results])
            errors = np.array([r[key][name]["error_std"] for r in results])
            entry[key] = {
                "coverage_90": float(np.mean(np.abs(errors) <= 1.645)),
                "max_move_std": float(moves.max()),
                "determined_share": float(np.mean([r[key][name]["determined"] for r in results])),
            }
        out["geometry"][name] = entry
    for key in ("free", "anchored"):
        worst = [max(abs(v["move_std"]) for v in r[key].values()) for r in results]
        out[key] = {
            "units_no_move_beyond_1_std": float(np.mean(np.array(worst) <= 1.0)),
            "worst_move_std": float(max(worst)),
            "geometry_coverage_90": float(
                np.mean([abs(v["error_std"]) <= 1.645 for r in results for v in r[key].values()])
            ),
            "distance_rms_um": float(
                np.sqrt(np.mean([r[key + "_distance_um"] ** 2 for r in results]))
            ),
        }
    out["exact_distance_rms_um"] = float(
        np.sqrt(np.mean([r["exact_distance_um"] ** 2 for r in results]))
    )
    return out


def print_reference(summary):
    print(
        "\n| reference parameter | 90 % coverage | called determined | median std (°) "
        "| most correlated with |"
    )
    print("| --- | --- | --- | --- | --- |")
    for name, row in summary["reference"].items():
        print(
            f"| `{name}` | {row['coverage_90']:.0%} | {row['determined_share']:.0%} "
            f"| {row['median_std_deg']:.2f} | `{row['correlated_with']}` |"
        )
    print(
        "\n| geometric parameter | 90 % coverage | largest move (std) | determined "
        "| taken as exact: coverage | largest move (std) | determined |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for name, entry in summary["geometry"].items():
        cells = []
        for key in ("free", "anchored"):
            row = entry[key]
            cells += [
                f"{row['coverage_90']:.0%}",
                f"{row['max_move_std']:.2f}",
                f"{row['determined_share']:.0%}",
            ]
        print(f"| `{name}` | " + " | ".join(cells) + " |")
    for key in ("free", "anchored"):
        print(f"{key}: {summary[key]}")
    print(f"exact reference, distance RMS: {summary['exact_distance_rms_um']:.1f} µm")


def reference_benchmark(args):
    """``--reference-errors N``: run, print, write the JSON."""
    start = time.perf_counter()
    jobs = [(i, args.seed, args.poses, not args.exact_optics) for i in range(args.reference_errors)]
    with ProcessPoolExecutor(args.workers) as pool:
        results = list(pool.map(run_reference_unit, jobs))
    print(f"{len(jobs)} units in {time.perf_counter() - start:.0f} s on {args.workers} workers")
    summary = summarise_reference(results)
    print_reference(summary)
    with open(args.out, "w", encoding="utf-8") as handle:
        json.dump({"args": vars(args), "summary": summary, "units": results}, handle, indent=1)
    print(f"wrote {args.out}")


#: The cases of ``--misspecified``.
CASES = ("control", "tolerances_2x", "spread", "emitters", "reference")

#: ``emitters``: per sensor (extra divergence °, extra source radius mm, LED pattern).
EMITTERS = ((3.0, 0.04, "two_gaussian"), (-2.5, -0.02, "cosine_power"))


def emitter_design(design):
    """The design with each sensor's own emitter of :data:`EMITTERS`."""
    models, sensors = dict(design.sensor_models), []
    for placement, (wider, larger, _) in zip(design.sensors, EMITTERS, strict=True):
        model = design.model_of(placement)
        own = model.with_(
            name=f"{model.name} ({placement.name})",
            divergence_deg=model.divergence_deg + wider,
            source_radius_mm=model.source_radius_mm + larger,
        )
        models[own.name] = own
        sensors.append(replace(placement, model=own.name))
    return design.replace(sensors=tuple(sensors), sensor_models=models)


def misspecified_truth(case, design, index, seed):
    """The built unit of one case, its flat-curve source per sensor and its reference."""
    surface = batch_surface(seed, index // BATCH)
    rng = stream_rng(seed, "tolerance_draw", index, MISSPECIFIED)
    options = {"seed": seed, "surface": surface, "model_form": ModelForm()}
    reference = (0.0, 0.0, 0.0)
    if case == "tolerances_2x":
        base = Tolerances()
        options["tolerances"] = replace(
            base,
            **{
                f.name: replace(getattr(base, f.name), scale=2 * getattr(base, f.name).scale)
                for f in fields(base)
                if isinstance(getattr(base, f.name), Spread)
            },
        )
    elif case == "spread":
        options["model_form"] = replace(ModelForm(), subsurface_mm=float(rng.uniform(0.15, 0.3)))
    elif case == "reference":
        reference = (*rng.uniform(-ZERO_LIMIT_DEG, ZERO_LIMIT_DEG, 2), rng.uniform(-1.0, 1.0))
    if case != "emitters":
        unit = build_unit(design, index, **options)
        return unit, (unit, unit), reference
    truth = emitter_design(design)
    built = [
        build_unit(
            truth, index, **{**options, "model_form": replace(ModelForm(), emitter_pattern=p)}
        )
        for _, _, p in EMITTERS
    ]
    spliced = np.concatenate([built[0].coefficients[..., :1], built[1].coefficients[..., 1:]], -1)
    return replace(built[0], coefficients=spliced), tuple(built), reference


def misspecified_unit(args):
    """One unit of one case identified from calibration data alone and with curves."""
    case, index, seed, n_poses = args
    design = default_design()
    plan = make_plan(design.workspace, "sobol", n_poses, seed=0)
    unit, sources, reference = misspecified_truth(case, design, index, seed)
    calibration = built_unit_protocol(unit, plan, n_validation=1, seed=seed).calibration
    read = read_through(calibration.angles_deg, reference)
    rng = stream_rng(seed, "built_protocol", index, FLAT_CURVES)
    curves = [Curve(k, CURVE_MM, sources[k].flat_curve(k, CURVE_MM, rng)) for k in range(2)]
    data = {"u": (calibration.volts, read)}
    out = {"case": case, "index": index, "spread_mm": unit.model_form.subsurface_mm}
    start = time.process_time()
    fits = {"alone": identify(design, data, profiles=False)}
    out["cpu_s"] = time.process_time() - start
    fits["curves"] = identify(design, data, curves={"u": curves}, profiles=False)
    for key, result in fits.items():
        truth = misspecified_truth_vector(design, unit, result.layout, reference)
        out[key] = {
            name: {
                "z": float((result.x[j] - truth[j]) / result.std[j]),
                "determined": bool(result.std[j] <= 0.5 * result.layout.prior_std()[j]),
            }
            for j, name in enumerate(result.layout.names())
            if np.isfinite(truth[j]) and scored(name)
        }
        out[key + "_distance_um"] = distance_error_um(result, unit)
    if case == "reference":
        exact = identify(design, {"u": (calibration.volts, calibration.angles_deg)}, profiles=False)
        rows, before = geometry_rows(fits["alone"]), geometry_rows(exact)
        out["move_std"] = max(
            abs(row["estimate"] - before[n]["estimate"]) / row["std"] for n, row in rows.items()
        )
    return out


def guarded_unit(args):
    """:func:`misspecified_unit`, or the refusal of its fit (a FitError), recorded."""
    try:
        return misspecified_unit(args)
    except FitError as exc:
        return {"case": args[0], "index": args[1], "error": str(exc)}


def scored(name):
    """Whether a parameter is scored: the geometry, the reference and the spread (not the
    read-out, the emitter, the surface or the model-form amplitudes: effective values)."""
    key = name.split(": ")[-1]
    if key.startswith(("form_", "reflectance", "specular")) or key.endswith(EFFECTIVE):
        return False
    return key.endswith(GEOMETRY)


def misspecified_truth_vector(design, unit, layout, reference):
    """The unit's true parameters in ``layout``'s order (NaN: no literal truth)."""
    base = truth_vector(design, unit, reference)
    spread = [unit.model_form.subsurface_mm - SUBSURFACE_NOMINAL_MM] * (
        len(layout.shared_names) - 2
    )
    return np.r_[base[:2], spread, base[2:], [np.nan] * len(layout.model_form_names)]


def summarise_misspecified(results):
    """Per case and fit: coverage of what is called determined, and of everything."""
    out = {}
    for case in CASES:
        rows = [r for r in results if r["case"] == case]
        if not rows:
            continue
        entry = {"units": len(rows), "cpu_s_median": float(np.median([r["cpu_s"] for r in rows]))}
        if case == "reference":
            moves = np.array([r["move_std"] for r in rows])
            entry["units_no_move_beyond_1_std"] = float(np.mean(moves <= 1.0))
            entry["worst_move_std"] = float(moves.max())
        for key in ("alone", "curves"):
            per = {}
            for name in rows[0][key]:
                z = np.array([r[key][name]["z"] for r in rows])
                called = np.array([r[key][name]["determined"] for r in rows])
                per[name.split(": ")[-1]] = {
                    "determined": int(called.sum()),
                    "coverage_determined": float(np.mean(np.abs(z[called]) <= 1.645))
                    if called.any()
                    else None,
                    "coverage_all": float(np.mean(np.abs(z) <= 1.645)),
                }
            hits = [
                abs(r[key][n]["z"]) <= 1.645
                for r in rows
                for n in r[key]
                if r[key][n]["determined"]
            ]
            entry[key] = {
                "parameters": per,
                "coverage_determined": float(np.mean(hits)) if hits else None,
                "n_determined": len(hits),
                "coverage_all": float(
                    np.mean([abs(r[key][n]["z"]) <= 1.645 for r in rows for n in r[key]])
                ),
                "distance_rms_um": float(
                    np.sqrt(np.mean([r[key + "_distance_um"] ** 2 for r in rows]))
                ),
            }
        out[case] = entry
    return out


def print_misspecified(summary):
    for case, entry in summary.items():
        print(f"\n== {case}: {entry['units']} units, fit CPU median {entry['cpu_s_median']:.1f} s")
        if "worst_move_std" in entry:
            print(
                f"   no geometric move beyond 1 std in {entry['units_no_move_beyond_1_std']:.0%} "
                f"of units (worst {entry['worst_move_std']:.2f} std)"
            )
        for key in ("alone", "curves"):
            fit = entry[key]
            cover = fit["coverage_determined"]
            print(
                f"   {key}: determined {fit['n_determined']}, coverage "
                f"{'-' if cover is None else f'{cover:.0%}'}, all {fit['coverage_all']:.0%}, "
                f"distance RMS {fit['distance_rms_um']:.1f} µm"
            )
            for name, row in fit["parameters"].items():
                c = row["coverage_determined"]
                print(
                    f"      {name:<32} determined {row['determined']:>3}  coverage "
                    f"{'  -' if c is None else f'{c:4.0%}'}  all {row['coverage_all']:4.0%}"
                )


def misspecified_benchmark(args):
    """``--misspecified N``: run every case, print, write the JSON."""
    start = time.perf_counter()
    cases = args.cases.split(",") if args.cases else CASES
    jobs = [(c, i, args.seed, args.poses) for c in cases for i in range(args.misspecified)]
    with ProcessPoolExecutor(args.workers) as pool:
        found = list(pool.map(guarded_unit, jobs))
    results = [r for r in found if "error" not in r]
    print(f"{len(jobs)} unit fits in {time.perf_counter() - start:.0f} s on {args.workers} workers")
    for failed in (r for r in found if "error" in r):
        print(f"fit refused: {failed}")
    summary = summarise_misspecified(results)
    print_misspecified(summary)
    with open(args.out, "w", encoding="utf-8") as handle:
        json.dump({"args": vars(args), "summary": summary, "units": results}, handle, indent=1)
    print(f"wrote {args.out}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--units", type=int, default=50)
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--poses", type=int, default=200)
    parser.add_argument("--validation", type=int, default=2000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", default="identify_benchmark.json")
    parser.add_argument(
        "--identifiability",
        type=int,
        metavar="N",
        help="print only the table of posterior/prior std over N units and stop",
    )
    parser.add_argument("--reference-zero", choices=("free", "fixed"), default="free")
    parser.add_argument(
        "--reference-errors",
        type=int,
        metavar="N",
        help="score N units recorded by references with errors outside the prior, and stop",
    )
    parser.add_argument(
        "--exact-optics", action="store_true", help="--reference-errors: no model-form error"
    )
    parser.add_argument(
        "--misspecified",
        type=int,
        metavar="N",
        help="score N units of each truth the prior does not know, and stop",
    )
    parser.add_argument("--cases", help=f"--misspecified: a comma list of {', '.join(CASES)}")
    args = parser.parse_args()
    free = args.reference_zero == "free"
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    if args.identifiability:
        identifiability_table(args.identifiability, args.seed, free)
        return
    if args.reference_errors:
        reference_benchmark(args)
        return
    if args.misspecified:
        misspecified_benchmark(args)
        return
    start = time.perf_counter()
    jobs = [(i, args.seed, args.poses, args.validation, free) for i in range(args.units)]
    with ProcessPoolExecutor(args.workers) as pool:
        results = list(pool.map(run_unit, jobs))
    print(f"{args.units} units in {time.perf_counter() - start:.0f} s on {args.workers} workers")
    figures = {key: summarise(results, key) for key in ("alone", "curves")}
    for key, label in (("alone", "calibration data alone"), ("curves", "with flat-target curves")):
        print_summary(label, figures[key])
    f_ok = [
        (not r["f_alone"]["identifiable"])
        or r["f_alone"]["interval_90"]["low"] <= r["f_true"] <= r["f_alone"]["interval_90"]["high"]
        for r in results
    ]
    f_hits = [
        r["f_alone"]["interval_90"]["low"] <= r["f_true"] <= r["f_alone"]["interval_90"]["high"]
        for r in results
    ]
    ratios = np.array([r["angle_ratio"] for r in results])
    fit, full = (np.array([r[k] for r in results]) for k in ("cpu_s_fit", "cpu_s_full"))
    figures["f"] = {
        "honest_share": float(np.mean(f_ok)),
        "interval_holds_truth_share": float(np.mean(f_hits)),
        "called_determined": int(sum(r["f_alone"]["identifiable"] for r in results)),
    }
    figures["angles_over_floor"] = {
        "median": np.median(ratios, axis=0).tolist(),
        "max": ratios.max(axis=0).tolist(),
    }
    figures["cpu_s_per_unit"] = {
        "fit_median": float(np.median(fit)),
        "fit_max": float(fit.max()),
        "with_profiles_and_model_form_median": float(np.median(full)),
    }
    print(f"\nf: {figures['f']}")
    print(f"angles / Cramér–Rao floor (pitch, roll): {figures['angles_over_floor']}")
    print(f"CPU seconds per unit (200 poses): {figures['cpu_s_per_unit']}")
    with open(args.out, "w", encoding="utf-8") as handle:
        json.dump({"args": vars(args), "figures": figures, "units": results}, handle, indent=1)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
