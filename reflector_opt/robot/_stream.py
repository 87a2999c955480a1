"""Live angles: each frame to each unit's pitch and roll with a 1σ per angle, and the tip.

Unit j of a frame is the j-th calibration (base first, as ``calibrate`` lists them). The angles
are the calibration's ``predict`` of the frame's voltages (and temperatures, where the
calibration is compensated), as ``estimate`` computes them
(:func:`~reflector_opt.calibration._unit_calibration.unit_angles`), and each angle's 1σ is
``estimate``'s (:func:`~reflector_opt.calibration._unit_calibration.angle_sigma`: the
calibration's cross-validated error, the voltage noise through the calibration's gradient and,
given the units' in-use terms, the stated conditions' bias at the frame's angles and
temperature: :mod:`~reflector_opt.calibration._in_use`).
:func:`stream` gives them frame by frame; :func:`estimate_block` a block of frames at once, with
the tip's pose (``reflector-opt stream``, :mod:`reflector_opt.workflow._stream`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from reflector_opt.calibration._segment import tip_angles, tip_pose
from reflector_opt.calibration._temperature import TemperatureCompensated
from reflector_opt.calibration._unit_calibration import EstimatedShape, angle_sigma, unit_angles
from reflector_opt.util._errors import InputError


class Angles(NamedTuple):
    """One frame's estimate."""

    #: The frame's counter.
    counter: int
    #: Each unit's pitch and roll, degrees, shape (n_units, 2).
    angles_deg: np.ndarray
    #: Their 1σ, degrees, shape (n_units, 2).
    sigma_deg: np.ndarray


def streamed_units(protocol, calibrations):
    """The calibrations of the frames' units: the first ``protocol.n_units``.

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
    return units


def estimate_block(frames, protocol, units, *, noise_v=0.0, link_length_mm=None, in_use=None):
    """A block of frames' angles and 1σ and, given a link length, the tip's pose.

    Parameters
    ----------
    frames : list of Frame
    protocol : reflector_opt.robot._protocol.Protocol
    units : list of UnitCalibration
        From :func:`streamed_units`.
    noise_v : float
        Voltage noise of one reading, V (1σ).
    link_length_mm : float or None
        Distance between the units' rotation centres, mm; None: no tip.
    in_use : list of InUseTerms, optional
        Each unit's in-use terms for the stated conditions
        (:func:`~reflector_opt.calibration._in_use.in_use_terms`, computed once), in its 1σ at
        the frame's angles and temperature; None: none.

    Returns
    -------
    EstimatedShape
        Keyed ``counter``; the tip's angles and position from the streamed units, base first;
        no 1σ where no calibration records its error (an ``AS_BUILT.json``).
    """
    volts = np.stack([protocol.volts(f) for f in frames]).reshape(len(frames), len(units), -1)
    temps = np.stack([f.temperature_c for f in frames]) if protocol.temperature else None
    at = [None if temps is None else temps[:, j] for j in range(len(units))]
    angles = np.stack([unit_angles(c, volts[:, j], at[j]) for j, c in enumerate(units)], 1)
    bias = [None] * len(units)
    if in_use is not None:
        bias = [t.bias_deg(angles[:, j], at[j]) for j, t in enumerate(in_use[: len(units)])]
    sigma = np.stack(
        [
            angle_sigma(c, volts[:, j], at[j], noise_v, bias_deg=bias[j])
            for j, c in enumerate(units)
        ],
        1,
    )
    tip = position = None
    if link_length_mm is not None:
        rotation, position = tip_pose(angles[..., 0], angles[..., 1], link_length_mm)
        tip = tip_angles(rotation)
    sigma = None if np.isnan(sigma).all() else sigma  # no calibration records its error
    counters = [str(f.counter) for f in frames]
    return EstimatedShape(
        "counter", counters, [c.unit for c in units], angles, tip, position, sigma
    )


def stream(frames, protocol, calibrations, *, noise_v=0.0, in_use=None):
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
    in_use : list of InUseTerms, optional
        One per calibration (:func:`estimate_block`).

    Yields
    ------
    Angles

    Raises
    ------
    InputError
        Frames with a unit the calibrations lack, or compensated units without temperatures.
    """
    units = streamed_units(protocol, calibrations)
    for frame in frames:
        shape = estimate_block([frame], protocol, units, noise_v=noise_v, in_use=in_use)
        yield Angles(frame.counter, shape.angles_deg[0], shape.sigma_deg[0])
