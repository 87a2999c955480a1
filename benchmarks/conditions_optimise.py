"""The design optimised for its operating conditions against the white-noise optimum.

    python benchmarks/conditions_optimise.py [--seeds 0 1 2] [--no-front] [--units 4]
                                             [--asymmetric]

On the built-in defaults, in the conditions of docs/conditions.md's "Designs for the
conditions" (``temperature_range_k = 5``, every other key at its default): the white-noise
optimum (``optimise``), the design optimised in the conditions (``optimise --conditions``) for
each seed, and the built-in default design, each with its worst-case total error in the
conditions on the budget's full 1° grid, the sources at its worst pose, its white-noise
resolution and its common drift; the wall time of each search; the temperature term checked
on built units (exact optics, as-built geometry, a poly5 calibration at the bench, read 5 K
away); what compensation adds (modulated drive, a temperature-aware calibration taken as
perfect) and the designs optimised for what it leaves; and the drift front (white-noise
objective against common drift) with the design optimised in the conditions beside it. The
figures of docs/conditions.md and docs/optimiser.md.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from reflector_opt.analysis._budget import error_budget, thermal_coefficients_of
from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.calibration._models import make_model
from reflector_opt.design._conditions import Conditions
from reflector_opt.model._operating import OperatingState
from reflector_opt.optimiser import Problem, optimise
from reflector_opt.optimiser._conditions import binding_sources, common_drift_deg
from reflector_opt.optimiser._drift_front import drift_front
from reflector_opt.tolerance._builtunit import build_unit

#: ±5 K, the rest default but the reference's zero: the 0.1° the docs' figures were measured
#: with (the paper's IMU's class, the default now, is a constant 3° every design pays alike)
WARM = Conditions().replace(temperature_range_k=5.0, reference_zero_deg=[0.1, 0.1])


def _timed(problem, seed):
    t0 = time.perf_counter()
    result = optimise(problem, seed=seed)
    return result, time.perf_counter() - t0


def _row(label, design, seconds=None):
    budget = error_budget(design, WARM)
    binding = binding_sources(budget)
    sources = ", ".join(
        f"{name} {e:.3f} ({100 * binding['shares'][name]:.0f} %)"
        for name, e in list(binding["sources_deg"].items())[:4]
    )
    metrics = evaluate_metrics(design)
    time_text = "" if seconds is None else f"{seconds:.1f}"
    print(
        f"| {label} | {budget.worst_case_deg:.3f} | {metrics.worst_pitch_deg:.4f} / "
        f"{metrics.worst_roll_deg:.4f} | {common_drift_deg(design):.3f} | "
        f"{binding['angle']} at {binding['pose_deg']} | {sources} | {time_text} |"
    )
    return budget


def _built_units(design, units):
    """Largest shift of the estimate at ±5 K over built units, and the budget's term, °."""
    thermal = thermal_coefficients_of(design.models)
    pitch, roll = np.meshgrid(np.linspace(-15, 15, 13), np.linspace(-15, 15, 13), indexing="ij")
    angles = np.column_stack([pitch.ravel(), roll.ravel()])
    worst = 0.0
    for index in range(units):
        unit = build_unit(design, index, seed=11)
        calibration = make_model("poly5").fit(unit.volts(angles[:, 0], angles[:, 1]), angles)
        bench = calibration.predict(unit.volts(angles[:, 0], angles[:, 1]))
        for dt in (5.0, -5.0):
            state = OperatingState(delta_t_k=dt, thermal=thermal)
            hot = calibration.predict(unit.volts(angles[:, 0], angles[:, 1], state))
            worst = max(worst, float(np.abs(hot - bench).max()))
    term = error_budget(design, WARM).sources["temperature"]
    return worst, max(term.pitch_max_deg, term.roll_max_deg)


def _compensation(designs):
    print("\n| design | as is | modulated drive | temperature compensated (±0 K) | both |")
    print("| --- | --- | --- | --- | --- |")
    cases = (
        WARM,
        WARM.replace(drive="modulated"),
        WARM.replace(temperature_range_k=0.0),
        WARM.replace(drive="modulated", temperature_range_k=0.0),
    )
    for label, design in designs.items():
        totals = " | ".join(f"{error_budget(design, c).worst_case_deg:.3f}" for c in cases)
        print(f"| {label} | {totals} |")


def _compensated_optima():
    """The designs optimised for what compensation leaves: the temperature term gone
    (temperature-aware calibration taken as perfect), then crosstalk and ambient light too."""
    cases = {
        "temperature compensated": WARM.replace(temperature_range_k=0.0),
        "temperature compensated, modulated drive": WARM.replace(
            temperature_range_k=0.0, drive="modulated"
        ),
    }
    for label, conditions in cases.items():
        result, seconds = _timed(Problem(conditions=conditions), 0)
        for name, design in (("optimised", result.design), ("default", _default())):
            budget = error_budget(design, conditions)
            shares = binding_sources(budget)["shares"]
            top = ", ".join(f"{k} {100 * v:.0f} %" for k, v in list(shares.items())[:3])
            print(f"  {label}, {name} design: {budget.worst_case_deg:.3f}° ({top})")
        print(f"    (search {seconds:.1f} s)")


def _asymmetric(seeds):
    """The search at ±5 K with the pair's azimuth and across offset free (a larger budget)."""
    from reflector_opt.optimiser import SearchBudget
    from reflector_opt.util._errors import InputError

    bounds = {"sensor_azimuth_deg": (0.0, 90.0), "centre_across_mm": (-2.0, 2.0)}
    for seed in seeds:
        problem = Problem(conditions=WARM, bounds=bounds)
        try:
            result = optimise(problem, seed=seed, budget=SearchBudget(popsize=10, maxiter=40))
        except InputError as exc:
            print(f"  seed {seed}: {exc}")
            continue
        print(f"  seed {seed}: {error_budget(result.design, WARM).worst_case_deg:.3f}°")


def _default():
    return Problem().baseline_design()


def _front(reference):
    t0 = time.perf_counter()
    front = drift_front(Problem(conditions=WARM), seed=0, reference=reference)
    seconds = time.perf_counter() - t0
    print(f"\ndrift front ({seconds:.0f} s):")
    print("| drift limit (°/1 %) | drift (°/1 %) | objective (°) | total at ±5 K (°) | design |")
    print("| --- | --- | --- | --- | --- |")
    for p in (*front.points, front.reference):
        limit = "none" if p.drift_limit_deg is None else f"{p.drift_limit_deg:.3f}"
        if p is front.reference:
            limit = "(optimised at ±5 K)"
        if not p.feasible:
            print(f"| {limit} | no design: {p.reason} | | | |")
            continue
        origin = "its own" if p.kept_from is None else f"{p.kept_from} (own run: {p.reason})"
        flag = " (dominated)" if p.dominated else ""
        print(
            f"| {limit} | {p.drift_deg:.3f} | {p.objective_deg:.4f} | "
            f"{p.worst_case_deg:.3f} | {origin}{flag} |"
        )


def main():
    """Print the comparison, the built-unit check, the compensation and the front."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0])
    parser.add_argument("--units", type=int, default=4)
    parser.add_argument("--no-front", action="store_true")
    parser.add_argument(
        "--asymmetric",
        action="store_true",
        help="also search with the pair's azimuth and across offset free (slow)",
    )
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()}")
    white, white_s = _timed(Problem(), 0)
    warm = {seed: _timed(Problem(conditions=WARM), seed) for seed in args.seeds}
    print(
        "| design | total at ±5 K (°) | white-noise 1σ pitch / roll (°) | drift (°/1 %) | "
        "worst at | sources there (°, share of the square) | search (s) |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- |")
    _row("default design", _default())
    _row("white-noise optimum", white.design, white_s)
    for seed, (result, seconds) in warm.items():
        _row(f"optimised at ±5 K, seed {seed}", result.design, seconds)
    first = warm[args.seeds[0]][0]
    print("\nbuilt units, temperature term (largest shift at ±5 K, °): measured / budget")
    for label, design in (("white-noise optimum", white.design), ("at ±5 K", first.design)):
        measured, predicted = _built_units(design, args.units)
        print(f"  {label}: {measured:.3f} / {predicted:.3f}")
    _compensation(
        {
            "default design": _default(),
            "white-noise optimum": white.design,
            "optimised at ±5 K": first.design,
        }
    )
    print("\ndesigns for what compensation leaves (worst-case total, sources at the worst):")
    _compensated_optima()
    if args.asymmetric:
        print("\nat ±5 K with the pair's azimuth and across offset free:")
        _asymmetric(args.seeds)
    if not args.no_front:
        _front(first)
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
