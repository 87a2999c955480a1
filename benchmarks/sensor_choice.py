"""The optimiser picks the part: the catalogue ranked on the default envelope, timed, and the
sensitivity of each part to its assumed figures.

    python benchmarks/sensor_choice.py                  # ranking + sensitivity tables
    python benchmarks/sensor_choice.py --no-sensitivity # the ranking and its time only
    python benchmarks/sensor_choice.py --workers 2 --seed 0

The ranking is ``choose_sensor(Problem(), shipped_catalogue())``: the built-in defaults (the
22 mm unit, white SLA resin, ±15°), every part, the default search budget, each part's search
a task on ``--workers`` spawned processes. The sensitivity tables refit each part with its
assumed emitter–detector spacing (the prior's centre) and its assumed emitter angle (the
prior's centre on tan θ) scaled by 0.75 and 1.25 (``benchmarks/fit_catalogue.py``), and
optimise the design again for the variants of the parts that fit the unit (all variants of all
parts as tasks of one pool); each row gives the variant's worst-case resolution, its predicted
calibration error and the rank it would take among the other parts' catalogue models.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from fit_catalogue import fitted_model

from reflector_opt.model._catalogue import shipped_catalogue
from reflector_opt.optimiser import Problem, SearchBudget
from reflector_opt.optimiser._sensor_choice import choose_sensor, rank_key
from reflector_opt.workflow._optimise_text import ranking_lines

#: The assumptions varied and their factors.
VARIANTS = (("spacing", 0.75), ("spacing", 1.25), ("angle", 0.75), ("angle", 1.25))


def ranking(workers, seed):
    """The whole catalogue ranked under the defaults; prints the table, the wall time and the
    load average before and after."""
    print("load average {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    t0 = time.perf_counter()
    choice = choose_sensor(
        Problem(), shipped_catalogue(), seed=seed, budget=SearchBudget(workers=workers)
    )
    wall = time.perf_counter() - t0
    print("\n".join(ranking_lines(choice.record)))
    print(f"\n{len(shipped_catalogue())} parts in {wall:.1f} s wall on {workers} processes")
    print("load average {:.2f} {:.2f} {:.2f}\n".format(*os.getloadavg()))
    return choice


def _variant(part, what, factor):
    kwargs = {"spacing_scale": factor} if what == "spacing" else {"angle_scale": factor}
    model, _ = fitted_model(part, **kwargs)
    name = f"{part.name} {what}×{factor:g}"
    return dataclasses.replace(part, name=name, model=model.with_(name=name))


def sensitivity(choice, workers, seed):
    """Refit every part with each assumption scaled, optimise those that fit; print tables."""
    fits = {row["part"] for row in choice.record["ranking"] if row["status"] == "ranked"}
    variants, rows = [], {}
    for part in shipped_catalogue():
        nominal, _ = fitted_model(part)
        rows[part.name] = [("nominal (refit)", nominal)]
        for what, factor in VARIANTS:
            v = _variant(part, what, factor)
            rows[part.name].append((f"{what} × {factor:g}", v.model))
            if part.name in fits:
                variants.append(v)
    t0 = time.perf_counter()
    resolution = {}
    if variants:
        budget = SearchBudget(workers=workers)
        result = choose_sensor(Problem(), variants, seed=seed, budget=budget)
        resolution = {r["part"]: r for r in result.record["ranking"]}
    print(f"sensitivity: {len(variants)} variants optimised in {time.perf_counter() - t0:.0f} s\n")
    rows_by_part = {r["part"]: r for r in choice.record["ranking"]}
    ranked = [r for r in choice.record["ranking"] if r["status"] == "ranked"]
    for part in shipped_catalogue():
        _table(part, rows[part.name], rows_by_part[part.name], resolution, ranked)


def _table(part, rows, nominal_row, resolution, ranked):
    print(f"**{part.name}**\n")
    print(
        "| variant | e (mm) | ω0 (mm) | θ (°) | G | usable (mm) | worst-case 1σ (°) | "
        "calibration RMS pitch / roll (°) | rank |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    m = part.model
    print(_line("catalogue", m, nominal_row, part.name, ranked))
    for label, model in rows:
        key = f"{part.name} {label.replace(' × ', '×')}"
        print(_line(label, model, resolution.get(key, "not optimised"), part.name, ranked))
    print()


def _line(label, m, row, name, ranked):
    lo, hi = m.range_mm
    return (
        f"| {label} | {m.emitter_detector_mm:.3f} | {m.source_radius_mm:.3f} | "
        f"{m.divergence_deg:.1f} | {m.current_gain:.3g} | {lo:.2f}–{hi:.2f} | "
        f"{_figures(row, name, ranked)} |"
    )


def _figures(row, name, ranked):
    """Worst-case 1σ, calibration error and the rank the variant would take among the other
    parts' catalogue models."""
    if isinstance(row, str):
        return f"{row} | — | —"
    if row["status"] != "ranked":
        return "does not fit | — | —"
    worst = max(row["worst_pitch_deg"], row["worst_roll_deg"])
    error = row["calibration_rms_deg"]
    others = [r for r in ranked if r["part"] != name]
    rank = 1 + sum(rank_key(r) < rank_key(row) for r in others)
    return f"{worst:.4f} | {error['pitch']:.3f} / {error['roll']:.3f} | {rank}"


def main(argv=None):
    """Run the ranking and the sensitivity tables."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--no-sensitivity", action="store_true")
    args = parser.parse_args(argv)
    choice = ranking(args.workers, args.seed)
    if not args.no_sensitivity:
        sensitivity(choice, args.workers, args.seed)


if __name__ == "__main__":
    main()
