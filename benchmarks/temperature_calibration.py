"""Temperature compensation on built units: the figures of docs/calibration.md ("Temperature").

Each built unit of the default design (exact optics, as-built geometry, its read-out gain and
offset, the design's noise; seed 5) is calibrated with poly5 on a 100-pose grid at T0 and 40
Sobol poses at T0 + 10 K, and validated at 2000 poses at T0 + 5 K, against its white-noise
error: the same form fitted at T0 and validated at T0 with the same noise draws. Twice: with
the generic temperature coefficients of model.temperature, and with two different parts
(neither generic). Prints the ratios, the fitted gain change per kelvin of each sensor with
its standard deviation, and the light path's (model.temperature's photocurrent factor over
the two calibration temperatures, relative to their mean). tests/calibration/test_temperature.py
asserts the bounds on the first two units.

    python benchmarks/temperature_calibration.py --units 4
"""

import argparse

import numpy as np

from reflector_opt.calibration._models import make_model
from reflector_opt.calibration._plans import make_plan
from reflector_opt.calibration._temperature import TemperatureCompensated
from reflector_opt.design import default_design
from reflector_opt.model._operating import OperatingState
from reflector_opt.model._temperature import ThermalCoefficients, photocurrent_factor
from reflector_opt.tolerance._builtunit import build_unit, crlb_floor_deg
from reflector_opt.util._seeds import stream_rng

#: The seed of the units and of every draw (util.seeds streams).
SEED = 5

PARTS = {
    "generic": ThermalCoefficients(),
    "two parts": (
        ThermalCoefficients(
            led_output_per_k=-0.008, detector_gain_per_k=0.001, dark_current_a=2e-7
        ),
        ThermalCoefficients(
            led_output_per_k=-0.003,
            detector_gain_per_k=0.003,
            forward_voltage_v_per_k=-0.0015,
            dark_current_a=5e-8,
            dark_doubling_k=8.0,
        ),
    ),
}


def _rms(error):
    return np.sqrt(np.mean(error**2, axis=0))


def light_path_per_k(model, thermal, reference_c):
    """c of Eq 1 that the light path obeys at 25 and 35 °C, relative to ``reference_c``."""
    d1, d2 = 25.0 - reference_c, 35.0 - reference_c
    f1, f2 = (float(photocurrent_factor(dt, thermal, model)) for dt in (0.0, 10.0))
    return (f2 - f1) / (f1 * d2 - f2 * d1)


def one_unit(design, unit, thermal):
    """Ratios to the white-noise error at T0 + 5 K (compensated, uncompensated) and at T0
    (compensated), the compensated error at T0 + 5 K over the unit's Cramér–Rao floor, and the
    fitted c ± std of each sensor."""
    base = make_plan(design.workspace, "grid", 100)
    warm_poses = make_plan(design.workspace, "sobol", 40, seed=2)
    rng = stream_rng(SEED, "thermal_plan", unit.index)
    cold = unit.record(base, rng)
    warm = unit.record(warm_poses, rng, state=OperatingState(delta_t_k=10.0, thermal=thermal))
    truth = stream_rng(SEED, "thermal_truth_poses", unit.index).uniform(-15, 15, (2000, 2))
    at = {
        dt: unit.record(
            truth,
            stream_rng(SEED, "thermal_truth_noise", unit.index),
            0.0,
            OperatingState(delta_t_k=dt, thermal=thermal),
        ).volts
        for dt in (0.0, 5.0)
    }
    plain = make_model("poly5").fit(cold.volts, cold.angles_deg)
    white = _rms(plain.predict(at[0.0]) - truth)
    model = TemperatureCompensated("poly5").fit(
        np.vstack([cold.volts, warm.volts]),
        np.vstack([cold.angles_deg, warm.angles_deg]),
        np.r_[np.full(len(base), 25.0), np.full(len(warm_poses), 35.0)],
    )
    warm_error = _rms(model.predict(at[5.0], np.full(len(truth), 30.0)) - truth)
    ratios = [
        warm_error / white,
        _rms(plain.predict(at[5.0]) - truth) / white,
        _rms(model.predict(at[0.0], np.full(len(truth), 25.0)) - truth) / white,
        warm_error / crlb_floor_deg(unit, truth),
    ]
    return white, ratios, model


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--units", type=int, default=2)
    args = parser.parse_args()
    design = default_design()
    units = [build_unit(design, i, seed=SEED) for i in range(args.units)]
    print(
        "unit  white ° (p/r)   compensated +5 K   uncompensated +5 K   compensated T0   "
        "compensated +5 K / Cramér–Rao floor   c %/K fitted ± std (light path)"
    )
    for name, thermal in PARTS.items():
        print(name)
        parts = thermal if isinstance(thermal, tuple) else (thermal, thermal)
        for unit in units:
            white, ratios, model = one_unit(design, unit, thermal)
            cells = "   ".join(f"{r[0]:5.2f} / {r[1]:4.2f}  " for r in ratios)
            t0 = model.reference_temperature_c_
            fitted = ", ".join(
                f"{100 * c:+.3f} ± {100 * sd:.3f} ({100 * light_path_per_k(m, t, t0):+.3f})"
                for c, sd, m, t in zip(*model.thermal_[:2], unit.design.models, parts, strict=True)
            )
            print(f"  {unit.index:<3} {white[0]:.3f} / {white[1]:.3f}   {cells} {fitted}")


if __name__ == "__main__":
    main()
