"""Synthetic lab data: what a built segment of a design would record, in the lab's formats.

A stand-in for measurements while none exist (examples, notebooks, tests of the lab
workflow): :func:`built_units` draws how each printed unit differs from the nominal design (a
per-sensor gain and offset), :func:`calibration_data` records each unit over the workspace
grid (the calibration CSV) and :func:`voltage_log` records the segment during one of the
paper's validation motions (the voltage log), with the design's noise and ADC. Write them
with :func:`reflector_opt.calibration._files.write_calibration_csv` and
:func:`reflector_opt.calibration._files.write_voltage_log`.
"""

import numpy as np

from reflector_opt.calibration._segment import PAPER_AMPLITUDE_DEG, validation_motion
from reflector_opt.calibration._simulation import record
from reflector_opt.model._noise import Mismatch


def built_units(design, n_units=None, *, seed=0, gain_sigma=0.02, offset_sigma_v=0.02):
    """Random per-sensor gain and offset of each unit of a built segment.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    n_units : int, optional
        Default ``design.mechanics.n_units``.
    seed : int
    gain_sigma : float
        Relative spread of the gain (0.02 = 2 %).
    offset_sigma_v : float
        Spread of the offset, V.

    Returns
    -------
    list of reflector_opt.model._noise.Mismatch
        One per unit, base first.
    """
    n_units = design.mechanics.n_units if n_units is None else int(n_units)
    rng = np.random.default_rng(seed)
    n_sensors = len(design.sensors)
    return [Mismatch.draw(rng, n_sensors, gain_sigma, offset_sigma_v) for _ in range(n_units)]


def calibration_data(design, units, *, step_deg=0.5, seed=0):
    """Calibration samples of every unit over the workspace grid (the calibration CSV).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    units : list of reflector_opt.model._noise.Mismatch
        From :func:`built_units`; unit labels are "1", "2", … in this order.
    step_deg : float
        Grid step, degrees (0.5° gives 61 × 61 poses for ±15°).
    seed : int

    Returns
    -------
    dict
        ``unit`` (n,) labels, ``volts`` (n, 2) V, ``angles_deg`` (n, 2) pitch, roll.
    """
    rng = np.random.default_rng(seed)
    poses = design.workspace.poses(step_deg)
    volts = [record(design, poses, rng, mismatch).volts for mismatch in units]
    return {
        "unit": np.repeat([str(i + 1) for i in range(len(units))], len(poses)),
        "volts": np.concatenate(volts),
        "angles_deg": np.tile(poses, (len(units), 1)),
    }


def voltage_log(
    design,
    units,
    axis="pitch",
    *,
    amplitude_deg=PAPER_AMPLITUDE_DEG,
    cycles=4,
    samples_per_cycle=200,
    seed=0,
):
    """Voltage log of the segment during one of the paper's validation motions.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    units : list of reflector_opt.model._noise.Mismatch
        From :func:`built_units`, base first.
    axis : {"pitch", "roll"}
    amplitude_deg : float
        Segment amplitude, degrees.
    cycles, samples_per_cycle : int
    seed : int

    Returns
    -------
    dict
        Rows of the log: ``sample`` (n,), ``unit`` (n,) labels, ``volts`` (n, 2) V; and the
        truth, ``angles_deg`` (n_samples, n_units, 2) pitch, roll of every unit.
    """
    pitch, roll = validation_motion(axis, len(units), amplitude_deg, cycles, samples_per_cycle)
    rng = np.random.default_rng(seed)
    volts = np.stack(
        [
            record(design, np.column_stack([pitch[:, j], roll[:, j]]), rng, mismatch).volts
            for j, mismatch in enumerate(units)
        ],
        axis=1,
    )
    n_samples, n_units = pitch.shape
    return {
        "sample": np.repeat(np.arange(n_samples), n_units),
        "unit": np.tile([str(j + 1) for j in range(n_units)], n_samples),
        "volts": volts.reshape(-1, 2),
        "angles_deg": np.stack([pitch, roll], axis=-1),
    }
