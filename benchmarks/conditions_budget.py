"""The error budget in use of the default and the optimised designs, per drive scheme.

    python benchmarks/conditions_budget.py

For the built-in default design and the design ``optimise`` writes for the defaults
(examples/data/design.json): the drift sensitivity (angle error per 1 % light-path change),
and the error budget (evaluate --conditions) on the bench defaults and in
examples/conditions.toml (±5 K) under each drive scheme. The figures of docs/conditions.md.
"""

from __future__ import annotations

from pathlib import Path

from reflector_opt.analysis._budget import drift_sensitivity, error_budget
from reflector_opt.design import default_design, load_design
from reflector_opt.design._conditions import Conditions, load_conditions

ROOT = Path(__file__).resolve().parents[1]


def _line(name, e):
    return (
        f"  {name:<13} {e.pitch_rms_deg:6.3f} {e.roll_rms_deg:6.3f} "
        f"{e.pitch_max_deg:6.3f} {e.roll_max_deg:6.3f}"
    )


def main():
    designs = {
        "default": default_design(),
        "optimised": load_design(ROOT / "examples" / "data" / "design.json"),
    }
    example = load_conditions(ROOT / "examples" / "conditions.toml")
    cases = {"bench defaults": Conditions()} | {
        f"example, {drive}": example.replace(drive=drive)
        for drive in ("dc", "multiplexed", "modulated")
    }
    for label, design in designs.items():
        print(f"{label} design: drift per 1 % (pitch RMS, roll RMS, pitch max, roll max, °)")
        for name, e in drift_sensitivity(design).items():
            print(_line(name, e))
        for case, conditions in cases.items():
            budget = error_budget(design, conditions)
            print(f" {case}: worst-case total {budget.worst_case_deg:.3f}°")
            for name, e in budget.sources.items():
                print(_line(name, e))
            print(_line("total", budget.total))


if __name__ == "__main__":
    main()
