"""Live angles: each frame to each unit's pitch and roll with a 1σ per angle.

Unit j of a frame is the j-th calibration (base first, as ``calibrate`` lists them). The angles
are the calibration's ``predict`` of the frame's voltages (and temperatures, where the
calibration is compensated), as ``estimate`` computes them. The 1σ of each angle k is

    σ_k² = e_k² + σ_V² · (J_k1² + J_k2²)

with e_k the calibration's cross-validated RMS error (its training RMS where the file holds no
cross-validation): the error of the map itself, measured against the reference; σ_V the
voltage noise of one reading, V; and J = ∂(pitch, roll)/∂(v1, v2) at the reading (central
differences, 1 µV steps), which carries that noise to the angles. e_k already holds the
calibration readings' own noise, so σ leans high by up to that part; it knows nothing of what
the in-use budget adds (temperature beyond the compensation, ambient light).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from reflector_opt.calibration._temperature import TemperatureCompensated
from reflector_opt.util._errors import InputError

#: The voltage step of the Jacobian's central differences, V.
STEP_V = 1e-6


class Angles(NamedTuple):
    """One frame's estimate."""

    #: The frame's counter.
    counter: int
    #: Each unit's pitch and roll, degrees, shape (n_units, 2).
    angles_deg: np.ndarray
    #: Their 1σ, degrees, shape (n_units, 2).
    sigma_deg: np.ndarray


def _predict(model, volts, temperature_c):
    if isinstance(model, TemperatureCompensated):
        return model.predict(volts, np.broadcast_to(temperature_c, volts.shape[:-1]))
    return model.predict(volts)


def _jacobian(model, volts, temperature_c):
    """∂(pitch, roll)/∂(v1, v2), deg/V, shape (2, 2): rows the angles."""
    steps = np.array([[STEP_V, 0.0], [-STEP_V, 0.0], [0.0, STEP_V], [0.0, -STEP_V]])
    a = _predict(model, volts + steps, temperature_c)
    return np.column_stack([a[0] - a[1], a[2] - a[3]]) / (2 * STEP_V)


def _calibration_error(calibration):
    cv = calibration.cross_validation
    if cv is not None:
        return np.asarray(cv["rms_deg"], dtype=float)
    model = calibration.model
    return np.asarray(getattr(model, "form_", model).training_rms_deg_, dtype=float)


def stream(frames, protocol, calibrations, *, noise_v=0.0):
    """Each frame's angles with their 1σ (module notes).

    Parameters
    ----------
    frames : iterable of Frame
        From :meth:`~reflector_opt.robot._protocol.Decoder.read` or ``feed``.
    protocol : reflector_opt.robot._protocol.Protocol
        Their layout (volts or codes, temperatures).
    calibrations : list of UnitCalibration
        One per unit of the frames, base first (more are allowed: the first ``n_units``).
    noise_v : float
        Voltage noise of one reading, V (1σ).

    Yields
    ------
    Angles

    Raises
    ------
    InputError
        Frames with a unit the calibrations lack, or compensated units without temperatures.
    """
    if protocol.n_units > len(calibrations):
        raise InputError(
            f"frames: {protocol.n_units} units, but the calibration has {len(calibrations)} "
            f"({', '.join(c.unit for c in calibrations)})"
        )
    units = calibrations[: protocol.n_units]
    thermal = [c.unit for c in units if isinstance(c.model, TemperatureCompensated)]
    if thermal and not protocol.temperature:
        raise InputError(
            f"frames: no temperatures, but unit(s) {', '.join(thermal)} are compensated"
        )
    errors = np.array([_calibration_error(c) for c in units])
    for frame in frames:
        volts = protocol.volts(frame)
        temps = frame.temperature_c if protocol.temperature else [None] * len(units)
        rows = list(zip(units, volts, temps, strict=True))
        angles = np.array([_predict(c.model, v, t) for c, v, t in rows])
        spread = np.array([(_jacobian(c.model, v, t) ** 2).sum(axis=1) for c, v, t in rows])
        yield Angles(frame.counter, angles, np.sqrt(errors**2 + noise_v**2 * spread))
