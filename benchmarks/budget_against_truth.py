"""The error budget's terms against the independent truth, term by term (docs/conditions.md).

    python benchmarks/budget_against_truth.py

For the default design and tests/data/design_6c47a9f.json (the sample optimised design as of
6c47a9f), each with its own parts and with VCNT2020 parts: each term's RMS by the budget and
by the truth (tests/independent/inuse.py: its own circuit, the published temperature curves,
the sphere's centre moved, its read-out's timing and the detectors' response for ambient
light and crosstalk under each drive, a nonlinear inversion per pose) on a 7 × 7 grid, and
the signed pose-by-pose gap |budget − truth| / |truth| that
tests/analysis/test_budget_against_truth.py holds under 25 % (a term whose truth is zero
prints "zero" when the budget's is zero too).
"""

from __future__ import annotations

import dataclasses
import logging
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from reflector_opt.analysis._budget import error_budget  # noqa: E402
from reflector_opt.design import default_design, load_design  # noqa: E402
from reflector_opt.design._conditions import Conditions  # noqa: E402
from tests.analysis.test_budget_against_truth import (  # noqa: E402
    LIGHT,
    _drive,
    ambient_states,
    gap,
    neighbour_states,
    seated_raster_truth,
)
from tests.independent.inuse import InUse, in_use_error_deg  # noqa: E402

STEP_DEG = 5.0


def _rms(errors):
    return np.sqrt(np.mean(np.asarray(errors) ** 2, axis=(-2,))).max(axis=0)


def _print_row(design, parts, label, predicted, truth):
    """One row: the budget's and the truth's RMS pitch / roll and their signed gap."""
    b, t = _rms(predicted), _rms(truth)
    print(
        f"{design:9} {parts:9} {label:27} {b[0]:.3f} / {b[1]:.3f}  "
        f"{t[0]:.3f} / {t[1]:.3f}  {100 * gap(predicted, truth):5.1f} %",
        flush=True,
    )


def main():
    logging.disable(logging.WARNING)  # the GE 6 E's rated tilt, once per design
    quiet = Conditions.quiet()
    designs = {
        "default": default_design(),
        "optimised": load_design(ROOT / "tests" / "data" / "design_6c47a9f.json"),
    }
    cases = {
        "temperature ±5 K": (
            quiet.replace(temperature_range_k=5.0),
            "temperature",
            lambda part, design, budget: [
                InUse(delta_t_k=dt, linear_output_per_k=None if part else 0.004)
                for dt in (5.0, -5.0)
            ],
        ),
        "free joint 30 µm": (
            quiet.replace(joint_clearance_um=30.0, tendon_preload_n=0.0),
            "play",
            lambda part, design, budget: [
                InUse(centre_shift_mm=tuple(0.015 * a)) for a in np.vstack([np.eye(3), -np.eye(3)])
            ],
        ),
        "supply 10 mV fixed": (
            quiet.replace(supply_change_mv=10.0),
            "supply",
            lambda part, design, budget: [InUse(supply_change_v=dv) for dv in (0.01, -0.01)],
        ),
        "supply 10 mV ratiometric": (
            quiet.replace(supply_change_mv=10.0, adc_reference="ratiometric"),
            "supply",
            lambda part, design, budget: [
                InUse(supply_change_v=dv, adc_reference="ratiometric") for dv in (0.01, -0.01)
            ],
        ),
    }
    for scheme in ("dc", "multiplexed", "modulated"):
        light = LIGHT.replace(drive=scheme)
        cases[f"ambient 1 + 0.5 mV {scheme}"] = (
            light,
            "ambient",
            lambda part, design, budget, light=light: ambient_states(design, light),
        )
        cases[f"crosstalk 0.5 % {scheme}"] = (
            light,
            "crosstalk",
            lambda part, design, budget: neighbour_states(budget),
        )
    print("design, parts, term: budget RMS pitch / roll, truth RMS pitch / roll, gap")
    for name, base in designs.items():
        for part in (None, "VCNT2020"):
            design = (
                base
                if part is None
                else base.replace(
                    sensors=tuple(dataclasses.replace(s, model=part) for s in base.sensors)
                )
            )
            for label, (conditions, source, states) in cases.items():
                budget = error_budget(design, conditions, step_deg=STEP_DEG)
                pitch, roll = budget.pitch_deg.ravel(), budget.roll_deg.ravel()
                drive = _drive(conditions) if source in ("ambient", "crosstalk") else None
                truth = np.stack(
                    [
                        in_use_error_deg(design, pitch, roll, s, drive=drive)
                        for s in states(part, design, budget)
                    ]
                )
                _print_row(
                    name, part or "own", label, budget.scenarios[source][: len(truth)], truth
                )

    c = 68.0  # the GE 6 E's normal class, seated by the preload
    for name, design in designs.items():
        budget = error_budget(design, quiet.replace(joint_clearance_um=c), step_deg=STEP_DEG)
        (truth,) = seated_raster_truth(design, budget, c, signs=(1.0,))
        _print_row(
            name, "own", "seated 68 µm, raster, pitching", budget.scenarios["play"][0], truth
        )


if __name__ == "__main__":
    main()
