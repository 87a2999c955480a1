"""A sensor facing a flat target: its modelled coupling and the correction to a measurement.

A flat target at normal incidence is how a sensor is characterised: the datasheet curve and
the lab measurement behind it (the paper's Fig. 2d) step the distance to a flat sheet and
record the output voltage. :func:`flat_coupling` is the model's account of that set-up
(paper Eq 4 with the emitter–detector offset, docs/model.md §2). A sensor fitted with
``method="interpolate"`` (:func:`reflector_opt.model._measured.fit_sensor_model`) carries the
measurement itself, a :class:`MeasuredCurve`, and :func:`flat_correction` scales the modelled
coupling by the measured-over-modelled ratio, so the model reproduces the measurement on a
flat target and keeps its own account of curvature and tilt.

The functions take a :class:`~reflector_opt.model._sensors.SensorModel`, whose
:meth:`~reflector_opt.model._sensors.SensorModel.flat_coupling` and
:meth:`~reflector_opt.model._sensors.SensorModel.flat_correction` call them.
"""

from dataclasses import dataclass

import numpy as np

from reflector_opt.model._optics import flat_target_coupling
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import json_record

#: Least spread of a curve's unclamped readings, V: a curve flatter than this carries no signal
#: of the distance (about 12 steps of a 12-bit converter at 3.3 V).
MIN_SIGNAL_V = 0.01


@dataclass(frozen=True)
class MeasuredCurve:
    """A measured output-voltage-versus-distance curve against a flat target.

    Parameters
    ----------
    distance_mm : tuple of float
        Distances to the flat target, strictly increasing, mm.
    volts : tuple of float
        Output voltage at each distance, V.
    reflectance : float
        Reflectance ρ of the target used for the measurement (0–1).
    specular_fraction : float
        Mirror-like share f of the target's reflectance (0–1; 1, the default, is a mirror,
        as curves were read before the surface model).
    """

    distance_mm: tuple[float, ...]
    volts: tuple[float, ...]
    reflectance: float = 0.9
    specular_fraction: float = 1.0

    def __post_init__(self):
        d, v = np.asarray(self.distance_mm, float), np.asarray(self.volts, float)
        if d.ndim != 1 or d.shape != v.shape or d.size < 4:
            raise InputError("measured curve: needs at least 4 (distance_mm, volts) points")
        if not (np.all(np.isfinite(d)) and np.all(np.isfinite(v))):
            raise InputError("measured curve: distances and volts must be finite numbers")
        if np.any(np.diff(d) <= 0):
            raise InputError("measured curve: distance_mm must be strictly increasing")
        if not 0 < self.reflectance <= 1:
            raise InputError("measured curve: reflectance must be in (0, 1]")
        if not 0 <= self.specular_fraction <= 1:
            raise InputError("measured curve: specular_fraction must be in [0, 1]")

    def to_dict(self):
        """JSON-ready dict."""
        return json_record(self)


def signal_readings(volts, model, what, *, least=4, clamp_margin_v=0.0):
    """The readings of a curve that carry the coupling; refuse a curve that carries none.

    The output is clamped at the supply (no light reaches the detector) and at saturation
    (:mod:`reflector_opt.model._electronics`): a reading there, or within ``clamp_margin_v``
    of either, says nothing of the coupling. A curve is refused when fewer than ``least``
    readings lie between the clamps, or when those vary by less than :data:`MIN_SIGNAL_V`
    (a constant output).

    Parameters
    ----------
    volts : array_like
        The curve's output voltages, V.
    model : reflector_opt.model._sensors.SensorModel
        The sensor whose circuit produced them: ``saturation_v`` and ``supply_v``.
    what : str
        The curve's name in messages, e.g. ``"measured curve"``.
    least : int, optional
        Fewest readings between the clamps that the use of the curve needs.
    clamp_margin_v : float, optional
        Readings within this many volts of a clamp count as clamped, V.

    Returns
    -------
    numpy.ndarray of bool
        True where a reading lies between the clamps, the shape of ``volts``.

    Raises
    ------
    InputError
        Naming ``what`` and the problem: every reading clamped, too few unclamped, or a flat
        curve.
    """
    v = np.asarray(volts, dtype=float)
    low, high = model.saturation_v + clamp_margin_v, model.supply_v - clamp_margin_v
    used = (v > low) & (v < high)
    n = int(used.sum())
    if n == 0 and v.size:
        raise InputError(
            f"{what}: every reading is clamped (at or below {low:.3g} V, saturation, or at or "
            f"above {high:.3g} V, the supply: no light); no reading carries the coupling"
        )
    if n < least:
        raise InputError(
            f"{what}: needs at least {least} readings between {low:.3g} and {high:.3g} V "
            f"(not clamped), found {n}"
        )
    spread = float(np.ptp(v[used]))
    if spread < MIN_SIGNAL_V:
        raise InputError(
            f"{what}: the output does not change with the distance (its readings between the "
            f"clamps span {1e3 * spread:.3g} mV, less than {1e3 * MIN_SIGNAL_V:g} mV); the "
            "curve carries no signal"
        )
    return used


def flat_coupling(model, distance_mm, reflectance=1.0, specular_fraction=1.0):
    """Modelled coupling against a flat target facing the sensor squarely.

    ``η(d) = ρ · [f · η_mirror(d) + (1 − f) · η_Lambert(d)]``
    (:func:`~reflector_opt.model._optics.flat_target_coupling`).

    Parameters
    ----------
    model : reflector_opt.model._sensors.SensorModel
        Gives the source radius ω0, divergence θ, detector area S_area and offset e.
    distance_mm : array_like
        Distance to the flat target, mm.
    reflectance : float, optional
        Target reflectance ρ (0–1).
    specular_fraction : float, optional
        Mirror-like share f of the target's reflectance (1: a mirror; 0: Lambertian).

    Returns
    -------
    numpy.ndarray
        Detected over emitted power (dimensionless).
    """
    return flat_target_coupling(distance_mm, model, reflectance, specular_fraction)


def flat_correction(model, distance_mm):
    """Measured over modelled flat-target coupling at each distance; 1 without a curve.

    The ratio at the measured points is interpolated between them with a monotone
    (PCHIP) interpolant. Points clamped at saturation or at the supply carry no coupling
    and are left out; beyond the measured distances the nearest point's ratio is used.

    Parameters
    ----------
    model : reflector_opt.model._sensors.SensorModel
        The sensor; its ``measured_curve`` (or None) and its electronics, which turn the
        measured voltages back into couplings.
    distance_mm : array_like
        Distance along the optical axis, mm (NaN stays NaN).

    Returns
    -------
    numpy.ndarray or float
        The factor (dimensionless), shape of ``distance_mm``; the float 1.0 without a curve.
    """
    curve = model.measured_curve
    if curve is None:
        return 1.0
    from scipy.interpolate import PchipInterpolator  # slow to import; only with a curve

    d, v = np.asarray(curve.distance_mm, dtype=float), np.asarray(curve.volts, dtype=float)
    unclamped = (v > model.saturation_v) & (v < model.supply_v)  # clamped points carry no η
    d = d[unclamped]
    modelled = flat_coupling(model, d, curve.reflectance, curve.specular_fraction)
    ratio = model.coupling_from_voltage(v[unclamped]) / modelled
    return PchipInterpolator(d, ratio)(np.clip(distance_mm, d[0], d[-1]))
