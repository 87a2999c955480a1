"""Lab files of two units recorded at several temperatures (fast model, model.temperature's
light path, per-unit read-out gain and offset, the design's noise), for the command tests."""

import numpy as np

from reflector_opt.calibration._files import write_calibration_csv, write_voltage_log
from reflector_opt.calibration._plans import make_plan
from reflector_opt.calibration._simulation import measure_with_design_noise
from reflector_opt.model._forward import voltages
from reflector_opt.model._noise import Mismatch
from reflector_opt.model._operating import OperatingState, apply_state

#: The units' read-out gain and offset.
UNITS = {"1": Mismatch((0.98, 1.01), (0.004, -0.008)), "2": Mismatch((1.02, 0.99), (-0.01, 0.0))}

#: Where each unit is calibrated: the grid at 25 °C, Sobol poses at 35 °C.
T0_C, WARM_C = 25.0, 35.0


def record(design, mismatch, poses, temperature_c, rng):
    """Voltages of a unit at poses (n, 2) and temperatures (n,), read out with noise."""
    clean = voltages(design, poses[:, 0], poses[:, 1])
    out = np.empty_like(clean)
    for t in np.unique(temperature_c):
        at = temperature_c == t
        out[at] = apply_state(clean[at], design.models, OperatingState(delta_t_k=t - T0_C))
    return measure_with_design_noise(design, mismatch.apply(out), rng)


def write_thermal_lab(design, folder, temperatures=(T0_C, WARM_C), seed=0):
    """Write ``data.csv`` (a 9 × 9 grid at the first temperature, 40 Sobol poses at each
    other) and ``log.csv`` (60 instants at 30 °C, with a temperature_c column); returns the
    log's true angles, shape (60, n_units, 2)."""
    rng = np.random.default_rng(seed)
    grid, sobol = make_plan(design.workspace, "grid", 81), make_plan(design.workspace, "sobol", 40)
    poses = np.vstack([grid, *([sobol] * (len(temperatures) - 1))])
    temperature = np.concatenate(
        [np.full(len(grid), temperatures[0]), *(np.full(40, t) for t in temperatures[1:])]
    )
    labels, volts = [], []
    for unit, mismatch in UNITS.items():
        labels += [unit] * len(poses)
        volts.append(record(design, mismatch, poses, temperature, rng))
    write_calibration_csv(
        folder / "data.csv",
        labels,
        np.vstack(volts),
        np.tile(poses, (2, 1)),
        np.tile(temperature, 2),
    )
    truth = rng.uniform(-14, 14, (60, len(UNITS), 2))
    log = np.stack(
        [
            record(design, m, truth[:, j], np.full(60, 30.0), rng)
            for j, m in enumerate(UNITS.values())
        ],
        axis=1,
    )
    sample = np.repeat(np.arange(60), len(UNITS))
    unit = np.tile(list(UNITS), 60)
    write_voltage_log(
        folder / "log.csv", sample, unit, log.reshape(-1, 2), np.full(len(unit), 30.0)
    )
    return truth
