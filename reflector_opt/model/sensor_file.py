"""A sensor model as data: the checks on its parameters and its JSON-ready dict form.

``design.json`` stores the sensor models defined in the design itself (e.g. fitted to a
measurement, :mod:`reflector_opt.model.measured`) under ``sensor_models``, each as the dict
:meth:`~reflector_opt.model.sensors.SensorModel.to_dict` writes; one fitted with
``method="interpolate"`` also carries its
:class:`~reflector_opt.model.flat_target.MeasuredCurve`. This module converts that dict form
in both directions and checks the values every
:class:`~reflector_opt.model.sensors.SensorModel` is built with, however it is built, each
problem an :class:`~reflector_opt.util.errors.InputError` naming the offending key.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import MISSING, asdict, fields

from reflector_opt.model.flat_target import MeasuredCurve
from reflector_opt.util.errors import InputError
from reflector_opt.util.limits import MAX_LENGTH_MM

__all__ = ["check_sensor", "sensor_from_dict", "sensor_to_dict"]

_POSITIVE = (
    "emitter_detector_mm",
    "source_radius_mm",
    "detector_area_mm2",
    "supply_v",
    "led_resistor_ohm",
    "load_resistor_ohm",
    "current_gain",
)


#: Parameters that are one number and need not be positive (checked below).
_OTHER_NUMBERS = ("divergence_deg", "led_forward_v", "saturation_v", "dark_current_a")
#: Physical lengths are at most MAX_LENGTH_MM.
_LENGTHS = ("emitter_detector_mm", "source_radius_mm")


def check_sensor(model):
    """Check a sensor model's parameters for physical sense.

    Parameters
    ----------
    model : reflector_opt.model.sensors.SensorModel

    Raises
    ------
    InputError
        A parameter that is not a finite number; a size, supply, resistor or gain that is not
        positive; a length or distance beyond ±:data:`~reflector_opt.util.limits.MAX_LENGTH_MM`;
        a divergence outside (0°, 90°); a range not ``0 <= min < max``; an LED forward
        voltage not below the supply; a saturation voltage outside ``[0, supply)``; a
        negative dark current.
    """
    where = f"sensor {model.name!r}"
    for field in (*_POSITIVE, *_OTHER_NUMBERS):
        _finite(getattr(model, field), f"{where}: {field}")
    for field in _POSITIVE:
        value = getattr(model, field)
        if value <= 0:
            raise InputError(f"{where}: {field} must be positive, got {value}")
    for field in _LENGTHS:
        value = getattr(model, field)
        if value > MAX_LENGTH_MM:
            raise InputError(
                f"{where}: {field} must be at most {MAX_LENGTH_MM:g} mm, got {value:g}"
            )
    if not 0.0 < model.divergence_deg < 90.0:
        raise InputError(f"{where}: divergence_deg must be in (0, 90)")
    try:
        lo, hi = model.range_mm
    except (TypeError, ValueError):
        raise InputError(
            f"{where}: range_mm must be (min, max) in mm, got {model.range_mm!r}"
        ) from None
    lo, hi = _finite(lo, f"{where}: range_mm"), _finite(hi, f"{where}: range_mm")
    if not 0.0 <= lo < hi <= MAX_LENGTH_MM:
        raise InputError(
            f"{where}: range_mm must satisfy 0 <= min < max <= {MAX_LENGTH_MM:g} mm, "
            f"got [{lo:g}, {hi:g}]"
        )
    if model.led_forward_v >= model.supply_v:
        raise InputError(f"{where}: led_forward_v must be below supply_v")
    if not 0.0 <= model.saturation_v < model.supply_v:
        raise InputError(f"{where}: saturation_v must be in [0, supply_v)")
    if model.dark_current_a < 0:
        raise InputError(
            f"{where}: dark_current_a must not be negative, got {model.dark_current_a}"
        )


def _finite(value, where):
    """``value`` as a float if it is a finite real number (not a bool)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InputError(f"{where} must be a number, got {value!r}")
    try:
        value = float(value)
    except OverflowError:
        raise InputError(f"{where} must be finite, got an integer too large for a float") from None
    if not math.isfinite(value):
        raise InputError(f"{where} must be finite, got {value}")
    return value


def sensor_to_dict(model):
    """A sensor model's parameters as a JSON-ready dict.

    Parameters
    ----------
    model : reflector_opt.model.sensors.SensorModel

    Returns
    -------
    dict
        One key per parameter; ``range_mm`` a list, ``measured_curve`` left out when the
        model has none.
    """
    d = asdict(model)
    d["range_mm"] = list(model.range_mm)
    if model.measured_curve is None:
        del d["measured_curve"]
    else:
        d["measured_curve"] = model.measured_curve.to_dict()
    return d


def sensor_from_dict(cls, data, where="sensor model"):
    """Build a sensor model from :func:`sensor_to_dict` output.

    Parameters
    ----------
    cls : type
        The sensor model class (:class:`~reflector_opt.model.sensors.SensorModel`); its
        dataclass fields are the keys, those without a default the required ones.
    data : dict
        The dict form.
    where : str, optional
        Where ``data`` comes from, to prefix error messages.

    Returns
    -------
    cls instance
        Raises :class:`~reflector_opt.util.errors.InputError` for a key that is unknown,
        missing or not of its type (``name`` any value, made a string; ``range_mm`` two
        numbers; ``measured_curve`` an object with ``distance_mm`` and ``volts``; every
        other key one number).
    """
    if not isinstance(data, dict):
        raise InputError(f"{where}: expected an object")
    declared = {f.name: f for f in fields(cls)}
    unknown = sorted(set(data) - set(declared))
    if unknown:
        raise InputError(f"{where}: unknown key(s) {', '.join(unknown)}")
    required = {
        k for k, f in declared.items() if f.default is MISSING and f.default_factory is MISSING
    }
    missing = sorted(required - set(data))
    if missing:
        raise InputError(f"{where}: missing key(s) {', '.join(missing)}")
    values = {}
    for key, value in data.items():
        if key == "name":
            values[key] = str(value)
        elif key == "range_mm":
            values[key] = _numbers(value, f"{where}.range_mm", 2)
        elif key == "measured_curve":
            values[key] = _curve(value, f"{where}.measured_curve")
        else:
            values[key] = _numbers([value], f"{where}.{key}", 1)[0]
    return cls(**values)


def _numbers(values, where, length):
    if not isinstance(values, list | tuple) or len(values) != length:
        raise InputError(f"{where}: expected {length} number(s)")
    if any(isinstance(v, bool) or not isinstance(v, int | float) for v in values):
        raise InputError(f"{where}: expected numbers, got {values!r}")
    return tuple(_finite(v, where) for v in values)


def _curve(value, where):
    if not isinstance(value, dict) or {"distance_mm", "volts"} - set(value):
        raise InputError(f"{where}: expected an object with distance_mm and volts")
    d, v = value["distance_mm"], value["volts"]
    return MeasuredCurve(
        distance_mm=_numbers(d, f"{where}.distance_mm", len(d) if isinstance(d, list) else -1),
        volts=_numbers(v, f"{where}.volts", len(v) if isinstance(v, list) else -1),
        reflectance=_numbers([value.get("reflectance", 0.9)], f"{where}.reflectance", 1)[0],
        specular_fraction=_numbers(
            [value.get("specular_fraction", 1.0)], f"{where}.specular_fraction", 1
        )[0],
    )
