"""Benchmark: the print loop — print, calibrate, identify, correct, print again.

Run from the repository root:

    PYTHONPATH=. python benchmarks/bench_print_loop.py [--json results.json]

Each scenario prints a batch of units of a design with the simulated print process
(:class:`reflector_opt.asbuilt._printprocess.PrintProcess`; the built units carry the
model-form error of :class:`reflector_opt.tolerance._model_form.ModelForm`, physics the
identification's model lacks), calibrates each on the 200-pose Sobol plan, identifies the
batch, pools it (the identification's model-form bias weighed as an uncertainty as
``correct`` does: the term the identification records, else simulated,
:mod:`reflector_opt.asbuilt._model_form_bias`), corrects the drawing (the ``correct``
subcommand's library calls, with the export's checks on the corrected parts), predicts the
next batch, and prints 5 new units from the corrected drawing and — with the same scatter
draws — 5 from the uncorrected one.

Reported per scenario (docs/print-loop.md):

* the systematic deviation of each sensor's Eq 3 distance over the workspace (1° grid): the
  batch mean of the units' distance against the design's, RMS over the poses, µm —
  *expected* (the process's systematic part alone, no scatter: what a batch mean tends to)
  and *observed* on 5-unit batches (their own scatter included: its floor is the scatter of
  one unit's distance over √5), before (uncorrected drawing) and after (corrected);
* the worst-case Cramér–Rao resolution: predicted gain (fast model, the identified units'
  deviations printed again) against the gain measured on the new units (exact optics with
  the form error; corrected against uncorrected with the same scatter draws);
* the margins (each sensor's distance window and distance to the response peak, the
  clearance; the smallest over the units, µm): predicted (the identified units printed again)
  and measured on the new units' true geometry, before and after.

``--curves`` identifies with each sensor's flat-target curve (measured before assembly on a
flat sample of the material), which pins the batch's sub-surface spread.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from reflector_opt import workflow
from reflector_opt.asbuilt._asbuiltfile import save_as_built
from reflector_opt.asbuilt._batchforecast import workspace_resolution
from reflector_opt.asbuilt._identification import identify
from reflector_opt.asbuilt._model_form_bias import MODES
from reflector_opt.asbuilt._printprocess import PrintProcess
from reflector_opt.asbuilt._problem import Curve
from reflector_opt.asbuilt._userloss import batch_figures
from reflector_opt.calibration._plans import make_plan
from reflector_opt.design import default_design
from reflector_opt.model._geometry import sensor_distance
from reflector_opt.tolerance._builtunit import built_unit_protocol
from reflector_opt.tolerance._model_form import ModelForm
from reflector_opt.util._seeds import stream_rng

#: (name, process, units identified).
SCENARIOS = (
    ("default process, 5 units", "default", 5),
    ("default process, 3 units", "default", 3),
    ("default process, 1 unit (assume systematic)", "default", 1),
    ("no systematic part, 5 units", "none", 5),
    ("default process, seats 0.15 mm deeper, 5 units", "deep", 5),
    ("radius −40 µm, centre moved, a seat tilted 1°, one 30 µm deep, 5 units", "cannot_write", 5),
    ("default process, sensor 1 seated 0.3 mm shallow (out of its window), 5 units", "window", 5),
)

#: Sensor-to-target distances of the flat-target curves (``--curves``), mm.
CURVE_MM = np.linspace(0.5, 3.0, 21)
SEED_FIRST, SEED_NEXT = 1, 2


def drawn_design():
    """The default design with its sphere centre at z = −1.2 mm: its parts export."""
    design = default_design()
    return design.replace(reflector=replace(design.reflector, centre_mm=(0.0, 0.0, -1.2)))


def processes(model_form):
    """The print processes of the scenarios."""
    return {
        "default": PrintProcess(model_form=model_form),
        "none": PrintProcess.scatter_only(model_form=model_form),
        "deep": PrintProcess(seat_standoffs_mm=(0.15, 0.15), model_form=model_form),
        "cannot_write": PrintProcess(
            shrink=0.0,
            centre_shift_mm=(0.03, -0.02, 0.04),
            radius_change_mm=-0.04,
            seat_tilts_deg=((1.0, 0.0),),
            seat_standoffs_mm=(0.0, 0.03),
            model_form=model_form,
        ),
        "window": PrintProcess(seat_standoffs_mm=(-0.3, 0.0), model_form=model_form),
    }


def distances(designs, step_deg=1.0):
    """Eq 3 distance of each design's sensors over the workspace grid: (n, P, R, S), mm."""
    out = []
    for d in designs:
        pitch, roll = d.workspace.grid(step_deg)
        r = d.reflector
        out.append(sensor_distance(d.positions_mm, r.centre_mm, r.radius_mm, pitch, roll))
    return np.array(out)


def deviation_um(designs, design):
    """Per sensor: RMS over the grid of (batch mean distance − design's), µm."""
    mean = distances(designs).mean(axis=0)
    error = mean - distances([design])[0]
    return 1e3 * np.sqrt(np.mean(error**2, axis=(0, 1)))


def floor_um(designs):
    """Per sensor: RMS over the grid of the units' distance std over √n, µm."""
    d = distances(designs)
    return 1e3 * np.sqrt(np.mean(d.std(axis=0, ddof=1) ** 2 / len(d), axis=(0, 1)))


def worst_resolution(units, step_deg=0.5):
    """Mean over the units of their worst-case resolution, degrees (exact optics)."""
    return float(
        np.mean([workspace_resolution(u.volts, u.design, step_deg)["worst"] for u in units])
    )


def identify_batch(design, units, n_poses, seed, curves=False):
    """Calibrate each unit on the Sobol plan and identify the batch (with ``curves``, each
    sensor's flat-target curve too: they pin the sub-surface spread)."""
    plan = make_plan(design.workspace, "sobol", n_poses)
    samples, flat = {}, {}
    for unit in units:
        protocol = built_unit_protocol(unit, plan, n_validation=1, seed=seed)
        label = str(unit.index + 1)
        samples[label] = (protocol.calibration.volts, protocol.calibration.angles_deg)
        rng = stream_rng(seed, "built_protocol", unit.index, 1)  # flat curves (bench_identify)
        flat[label] = [Curve(k, CURVE_MM, unit.flat_curve(k, CURVE_MM, rng)) for k in range(2)]
    return identify(design, samples, curves=flat if curves else None, profiles=False)


def margins(figures):
    """Window, peak (per sensor) and clearance margins of :func:`batch_figures`, µm."""
    return [1e3 * v for v in (*figures["window_mm"], *figures["peak_mm"], figures["clearance_mm"])]


def correct(design, result, n_units, mode):
    """``reflector-opt correct``'s library call on the batch's ``AS_BUILT.json`` (the parts
    exported, without pictures, into a folder removed after), and its wall time, s."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "AS_BUILT.json"
        save_as_built(result, path, source="bench", batch="A")
        started = time.perf_counter()
        run = workflow.correct(
            path, design=design, assume_systematic=n_units < 3, model_form=mode, preview=False
        ).write(Path(folder) / "next")
        return run, time.perf_counter() - started


def scenario(name, process, n_units, cache, args):
    """One scenario's figures (see the module docstring)."""
    design = drawn_design()
    started = time.perf_counter()
    first, uncorrected = cache[process]
    result = identify_batch(design, first[:n_units], args.poses, SEED_FIRST, args.curves)
    identified = time.perf_counter() - started
    run, corrected_s = correct(design, result, n_units, args.model_form)
    mean, correction, drawing, prediction, figures = (
        run.mean,
        run.correction,
        run.design,
        run.prediction,
        run.figures,
    )
    corrected = args.process[process].print_batch(drawing, args.next_units, seed=SEED_NEXT)
    systematic = [args.process[process].systematic_design(d) for d in (design, drawing)]
    before_res, after_res = worst_resolution(uncorrected), worst_resolution(corrected)
    measured = before_res / after_res
    return {
        "scenario": name,
        "units_identified": n_units,
        "noise_inflation": float(result.inflation),
        "scatter_factor": mean.scatter_factor,
        "model_form": list(mean.model_form),
        "determined": len(mean.directions),
        "chi2": correction.chi2,
        "threshold": correction.threshold,
        "corrected_directions": int(sum(correction.applied)),
        "changed": {k: r["change"] for k, r in correction.rows().items() if r["change"]},
        "distance_um": {
            "expected_before": deviation_um(systematic[:1], design).tolist(),
            "expected_after": deviation_um(systematic[1:], design).tolist(),
            "observed_first_batch": deviation_um([u.design for u in first], design).tolist(),
            "observed_before": deviation_um([u.design for u in uncorrected], design).tolist(),
            "observed_after": deviation_um([u.design for u in corrected], design).tolist(),
            "floor": floor_um([u.design for u in uncorrected]).tolist(),
        },
        "resolution_deg": {
            "predicted_without": prediction["without"]["worst_resolution_deg"]["mean"],
            "predicted_with": prediction["with"]["worst_resolution_deg"]["mean"],
            "predicted_gain": prediction["gain"],
            "measured_before": before_res,
            "measured_after": after_res,
            "measured_gain": measured,
            "confirmed_10pc": bool(abs(measured / prediction["gain"] - 1.0) <= 0.10),
        },
        "margins_um": {
            "predicted_without": margins(figures["without"]),
            "predicted_with": margins(figures["with"]),
            "measured_before": margins(
                batch_figures([(u.design, u.mismatch) for u in uncorrected])
            ),
            "measured_after": margins(batch_figures([(u.design, u.mismatch) for u in corrected])),
        },
        "step": correction.step,
        "given_up": list(correction.given_up),
        "spread_mm": result.shared_parameters()["subsurface_mm"]["estimate"],
        "calibration_rms_deg": {
            "predicted_without": prediction["without"]["calibration_rms_deg"],
            "predicted_with": prediction["with"]["calibration_rms_deg"],
        },
        "seconds": {
            "identify": identified,
            "correct": corrected_s,
            "total": time.perf_counter() - started,
        },
    }


def print_row(row):
    """The scenario's figures, in a few lines."""
    d, r = row["distance_um"], row["resolution_deg"]

    def pair(key):
        return "/".join(f"{v:.1f}" for v in d[key])

    ratio = [
        b / a if a > 0 else float("inf")
        for b, a in zip(d["expected_before"], d["expected_after"], strict=True)
    ]
    print(f"\n== {row['scenario']}")
    print(
        f"  s² {row['noise_inflation']:.2f}, scatter {row['scatter_factor']:.2f}× tolerances, "
        f"{row['determined']} determined, χ² {row['chi2']:.1f} (threshold {row['threshold']:.1f}), "
        f"{row['corrected_directions']} corrected"
    )
    print(
        f"  distance deviation S1/S2, µm: expected {pair('expected_before')} → "
        f"{pair('expected_after')} (×{ratio[0]:.2f}/×{ratio[1]:.2f}); observed "
        f"{pair('observed_before')} → {pair('observed_after')} (floor {pair('floor')}; first "
        f"batch {pair('observed_first_batch')})"
    )
    print(
        f"  worst resolution: predicted {r['predicted_without']:.4f}° → {r['predicted_with']:.4f}° "
        f"(gain {r['predicted_gain']:.3f}), measured {r['measured_before']:.4f}° → "
        f"{r['measured_after']:.4f}° (gain {r['measured_gain']:.3f}); within 10 %: "
        f"{r['confirmed_10pc']}"
    )
    m = row["margins_um"]

    def um(key):
        return "/".join(f"{v:.0f}" for v in m[key])

    print(
        f"  margins (window S1/S2, peak S1/S2, clearance), µm: predicted "
        f"{um('predicted_without')} → {um('predicted_with')}; measured "
        f"{um('measured_before')} → {um('measured_after')}"
    )
    print(f"  step {row['step']:.3g}; given up: {'; '.join(row['given_up']) or 'nothing'}")
    print(f"  sub-surface spread found: {row['spread_mm']:.3f} mm")
    print(f"  model form from: {', '.join(row['model_form']) or 'nowhere (model trusted)'}")
    seconds = row["seconds"]
    print(
        f"  {seconds['total']:.0f} s (identification {seconds['identify']:.0f} s, correct "
        f"{seconds['correct']:.1f} s)"
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=200, help="calibration poses per unit")
    parser.add_argument("--next-units", type=int, default=5, help="units of the next batch")
    parser.add_argument("--no-form-error", action="store_true", help="exact optics only")
    parser.add_argument(
        "--model-form",
        choices=MODES,
        default="auto",
        help="as correct's option: the identification's term, else simulated (auto); "
        "simulated; none (trust the model)",
    )
    parser.add_argument(
        "--curves", action="store_true", help="identify with each sensor's flat-target curve"
    )
    parser.add_argument("--only", help="run the scenarios whose name contains this text")
    parser.add_argument("--json", help="write the figures to this file")
    args = parser.parse_args()
    args.process = processes(None if args.no_form_error else ModelForm())
    print(f"load average before: {os.getloadavg()[0]:.2f} (2 cores shared)")
    design, cache, rows = drawn_design(), {}, []
    for name, process, n_units in SCENARIOS:
        if args.only and args.only not in name:
            continue
        if process not in cache:
            p = args.process[process]
            cache[process] = (
                p.print_batch(design, 5, seed=SEED_FIRST),
                p.print_batch(design, args.next_units, seed=SEED_NEXT),
            )
        rows.append(scenario(name, process, n_units, cache, args))
        print_row(rows[-1])
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(rows, f, indent=2, ensure_ascii=False)


if __name__ == "__main__":
    main()
