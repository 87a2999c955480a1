"""What each imperfection a temperature compensation does not see costs on built units, and
what the recommended protocol leaves (docs/conditions.md, "Temperature compensation").

    python benchmarks/thermometer_costs.py --units 2

The default design and tests/data/design_6c47a9f.json (the sample optimised design), each
unit calibrated with auto on the 196-pose grid at T0 = 25 °C and 100 Sobol poses at T0 − 10 K
and T0 + 10 K (``plan-calibration --temperature-range 10``'s layout), validated at ΔT = −10,
−5, 0, 5, 10 K (:func:`reflector_opt.tolerance._thermalplan.thermometer_costs`). Four truths
of the light path: the package's (``apply_state``) with the parts' catalogue figures
(NJL5901R-2: +0.4 %/K, curvature −5·10⁻⁵ /K² assumed) and with the generic coefficients the
plan uses; and tests/independent/inuse.py's own circuit and published curves, TCRT5000 and
CNY70 (their dome-shaped relative output as a spline through the read-off points, V_F(T, I_F)
solved in the LED loop, the dark current doubling every 6.5 K). Prints each row's RMS over
the white-noise error (the same poses all at T0), the worse angle at the worst temperature
and sign: without the protocol / with it, and the thermometer error the protocol's form can
take within 1.5×.
"""

import argparse
import logging
import sys
from pathlib import Path

import numpy as np

from reflector_opt.calibration._plans import make_plan
from reflector_opt.calibration._simulation import rig_record
from reflector_opt.design import default_design
from reflector_opt.design._design import load_design
from reflector_opt.model._temperature import ThermalCoefficients
from reflector_opt.tolerance._thermalplan import COST_ROWS, ThermalPrediction, thermometer_costs

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from tests.independent import inuse  # noqa: E402

#: The range of use, K, and the poses at each end.
RANGE_K, EXTRA_POSES = 10.0, 100


def inuse_truth(part_name):
    """A truth through inuse.py's circuit with a published part's curves: each sensor's
    photocurrent scaled by k(T)·I_F(T)/I_F(25 °C), its dark current grown, clipped as the
    circuit clips; the unit's read-out gain and offset, the design's noise."""
    part = inuse.PARTS[part_name]

    def record(unit, poses, rng, reference_sigma_deg, delta_t_k):
        models, mismatch = unit.design.models, unit.mismatch
        dts = np.broadcast_to(np.asarray(delta_t_k, dtype=float), (len(models),))

        def volts(pitch, roll):
            v = (unit.volts(pitch, roll) - mismatch.offset_v) / mismatch.gain
            out = np.empty_like(v)
            for k, (m, dt) in enumerate(zip(models, dts, strict=True)):
                t = 25.0 + dt
                drive = inuse.led_current_a(part, m, t, m.supply_v) / inuse.led_current_a(
                    part, m, 25.0, m.supply_v
                )
                photo = (m.supply_v - v[..., k]) / m.load_resistor_ohm - m.dark_current_a
                grown = inuse.dark_current_a(part, m, t) - inuse.dark_current_a(part, m, 25.0)
                current = photo * float(inuse.relative_output(part, t)) * drive + grown
                current += m.dark_current_a
                out[..., k] = np.clip(
                    m.supply_v - current * m.load_resistor_ohm, m.saturation_v, m.supply_v
                )
            return mismatch.apply(out)

        return rig_record(volts, unit.design, poses, rng, reference_sigma_deg)

    return record


TRUTHS = {
    "parts' figures": {},
    "generic": {"thermal": ThermalCoefficients()},
    "TCRT5000 (inuse)": {"record": inuse_truth("TCRT5000")},
    "CNY70 (inuse)": {"record": inuse_truth("CNY70")},
}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--units", type=int, default=2)
    args = parser.parse_args()
    logging.disable(logging.WARNING)  # the GE 6 E's rated tilt
    designs = {
        "default": default_design(),
        "optimised": load_design(ROOT / "tests" / "data" / "design_6c47a9f.json"),
    }
    prediction = ThermalPrediction(
        "both", EXTRA_POSES, (-RANGE_K, RANGE_K), np.zeros((5, 2)), np.zeros(2)
    )
    rows = list(COST_ROWS)
    print(f"±{RANGE_K:g} K, {args.units} units; without / with the protocol (× white-noise error)")
    print(f"{'design':10} {'truth':18}" + "".join(f"{r:>22}" for r in rows) + "  allowed error")
    for name, design in designs.items():
        base = make_plan(design.workspace, "grid", 196)
        for truth, options in TRUTHS.items():
            study = thermometer_costs(design, base, prediction, n_units=args.units, **options)
            cells = "".join(f"{a:>14.2f} / {b:<5.2f}" for a, b in (study.ratio[r] for r in rows))
            print(f"{name:10} {truth:18}{cells}  {study.allowed_error_k:.2f} K")


if __name__ == "__main__":
    main()
