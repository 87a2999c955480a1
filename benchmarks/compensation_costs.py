"""What a temperature-aware calibration's thermometer costs: the budget's temperature term
with each error a compensation cannot see (docs/conditions.md, "Temperature compensation").

    python benchmarks/compensation_costs.py

On tests/data/design_6c47a9f.json (the sample optimised design as of 6c47a9f) with its own
parts (NJL5901R-2, assumed curvature −5e-5 /K²) and with VCNT2020 parts (published curve),
±5 K: the temperature term RMS pitch / roll, and the worst angle's RMS of temperature and
noise together over the noise alone (the Cramér–Rao floor).
"""

import dataclasses
import logging
from pathlib import Path

from reflector_opt.analysis._budget import error_budget
from reflector_opt.design._conditions import Conditions
from reflector_opt.design._design import load_design

ROOT = Path(__file__).resolve().parents[1]


def main():
    logging.disable(logging.WARNING)  # the GE 6 E's rated tilt
    d = load_design(ROOT / "tests" / "data" / "design_6c47a9f.json")
    v = d.replace(sensors=tuple(dataclasses.replace(s, model="VCNT2020") for s in d.sensors))
    q = Conditions.quiet().replace(temperature_range_k=5.0)
    on = q.replace(temperature_compensated=True)
    cases = {
        "uncompensated ±5 K": q,
        "compensated, a perfect thermometer": on,
        "compensated, the defaults (0.5 K, 30 s at 0.5 K/min, 0.5 K)": Conditions().replace(
            temperature_range_k=5.0, temperature_compensated=True
        ),
        "compensated, thermometer 1 K off": on.replace(thermometer_offset_k=1.0),
        "compensated, 60 s behind at 1 K/min": on.replace(
            thermometer_lag_s=60.0, temperature_rate_k_per_min=1.0
        ),
        "compensated, S1 and S2 1 K apart": on.replace(strip_gradient_k=1.0),
        "compensated, 0.1 K, 5 s at 0.1 K/min, 0.1 K apart": on.replace(
            thermometer_offset_k=0.1,
            thermometer_lag_s=5.0,
            temperature_rate_k_per_min=0.1,
            strip_gradient_k=0.1,
        ),
    }
    for parts, design in (("NJL5901R-2", d), ("VCNT2020", v)):
        for label, conditions in cases.items():
            budget = error_budget(design, conditions)
            t, n = budget.sources["temperature"], budget.sources["noise"]
            ratio = max(
                (t.pitch_rms_deg**2 + n.pitch_rms_deg**2) ** 0.5 / n.pitch_rms_deg,
                (t.roll_rms_deg**2 + n.roll_rms_deg**2) ** 0.5 / n.roll_rms_deg,
            )
            print(
                f"{parts:10} {label:58} {t.pitch_rms_deg:.3f} / {t.roll_rms_deg:.3f}  "
                f"{ratio:.2f}× the floor"
            )


if __name__ == "__main__":
    main()
