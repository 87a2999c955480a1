"""The main job in use: the default design, the white-noise optimum and the design optimised in
the default conditions, each read under every drive and calibration, in the default conditions.

    python benchmarks/main_job_in_use.py

The default conditions (``Conditions()``: ±2 K, the GE 6 E at its normal clearance under 1 N
of preload, 10 mV of supply, the paper's IMU as reference, the parts' published figures and
assumed ones at their unfavourable end) are what README's main command would design for with
an in-use objective. Prints the wall time of one white-noise search and of one in-use search
in the same run (one worker, seed 0) and their ratio; then, per design, each drive at 10 kSa/s
and at 300 Sa/s (where the NJL5901R-2's detectors settle), uncompensated and
temperature-compensated: the worst case in use on the budget's 1° grid, the frame rate and the
three largest sources; and the worst case with the angle reference's zero stated as 0 (what
the geometry alone changes). The figures of docs/optimiser.md, "The main job in use".
"""

from __future__ import annotations

import time

from reflector_opt.analysis.budget import error_budget
from reflector_opt.design.conditions import Conditions
from reflector_opt.design.defaults import default_design
from reflector_opt.optimise import Problem, optimise
from reflector_opt.optimise.search import SearchBudget

DRIVES = (
    ("dc", 10000.0),
    ("multiplexed", 10000.0),
    ("multiplexed", 300.0),
    ("modulated", 10000.0),
    ("modulated", 300.0),
)


def _searched(problem, budget):
    start = time.perf_counter()
    result = optimise(problem, seed=0, budget=budget)
    return result.design, time.perf_counter() - start


def main():
    budget, conditions = SearchBudget(workers=1), Conditions()
    white, t_white = _searched(Problem(), budget)
    in_use, t_in_use = _searched(Problem(conditions=conditions), budget)
    print(
        f"one search: white-noise {t_white:.1f} s, in use {t_in_use:.1f} s, "
        f"ratio {t_in_use / t_white:.2f}"
    )
    designs = {
        "default design": default_design(),
        "white-noise optimum": white,
        "optimised in use (dc)": in_use,
    }
    for name, design in designs.items():
        for drive, rate in DRIVES:
            for compensated in (False, True):
                changed = conditions.replace(
                    drive=drive, sample_rate_hz=rate, temperature_compensated=compensated
                )
                b = error_budget(design, changed)
                top = sorted(
                    ((k, max(e.pitch_rms_deg, e.roll_rms_deg)) for k, e in b.sources.items()),
                    key=lambda item: -item[1],
                )[:3]
                sources = ", ".join(f"{k} {v:.3f}°" for k, v in top)
                print(
                    f"{name} | {drive} at {rate:g} Sa/s | compensated {compensated} | "
                    f"worst {b.worst_case_deg:.3f}° | {b.drive.frame_rate_hz:.0f} frames/s | "
                    f"{sources}"
                )
        stated = error_budget(design, conditions.replace(reference_zero_deg=[0.0, 0.0]))
        print(f"{name} | dc, the reference's zero stated 0 | worst {stated.worst_case_deg:.3f}°")


if __name__ == "__main__":
    main()
