"""A sensor model as data: the checks on its parameters and its JSON-ready dict form.

``design.json`` stores the sensor models defined in the design itself (e.g. fitted to a
measurement, :mod:`reflector_opt.model._measured`) under ``sensor_models``, each as the dict
:meth:`~reflector_opt.model._sensors.SensorModel.to_dict` writes; one fitted with
``method="interpolate"`` also carries its
:class:`~reflector_opt.model._flat_target.MeasuredCurve`. This module converts that dict form
in both directions and checks the values every
:class:`~reflector_opt.model._sensors.SensorModel` is built with, however it is built, each
problem an :class:`~reflector_opt.util._errors.InputError` naming the offending key.
"""

from dataclasses import asdict
from typing import Annotated

import msgspec
from msgspec import Meta

from reflector_opt.model._flat_target import MeasuredCurve, signal_readings
from reflector_opt.util import _schema as schema
from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import MAX_LENGTH_MM, check_finite

#: Most points of a measured curve.
MAX_CURVE_POINTS = 100_000

_Distance = Annotated[float, Meta(ge=0, le=MAX_LENGTH_MM, description="mm")]
_Length = Annotated[float, Meta(gt=0, le=MAX_LENGTH_MM, description="mm")]
_Voltage = Annotated[float, Meta(ge=0, le=1e3, description="V")]
_Resistance = Annotated[float, Meta(gt=0, le=1e12, description="Ω")]

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
    model : reflector_opt.model._sensors.SensorModel

    Raises
    ------
    InputError
        A parameter that is not a finite number; a size, supply, resistor or gain that is not
        positive; a length or distance beyond ±:data:`~reflector_opt.util._limits.MAX_LENGTH_MM`;
        a divergence outside (0°, 90°); a range not ``0 <= min < max``; an LED forward
        voltage not below the supply; a saturation voltage outside ``[0, supply)``; a
        negative dark current; a package that is not three positive lengths; a measured curve
        that carries no signal (fewer than 2 readings between the clamps, or those flat:
        :func:`~reflector_opt.model._flat_target.signal_readings`).
    """
    where = f"sensor {model.name!r}"
    for field in (*_POSITIVE, *_OTHER_NUMBERS):
        check_finite(getattr(model, field), f"{where}: {field}")
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
    lo, hi = check_finite(lo, f"{where}: range_mm"), check_finite(hi, f"{where}: range_mm")
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
    if model.package_mm is not None:
        _check_package(model.package_mm, f"{where}: package_mm")
    if model.measured_curve is not None:  # its correction needs two readings with a signal
        signal_readings(model.measured_curve.volts, model, f"{where}: measured_curve", least=2)


def _check_package(package, where):
    """Refuse a package that is not three positive lengths of at most MAX_LENGTH_MM."""
    try:
        sizes = [check_finite(v, where) for v in package]
    except TypeError:
        raise InputError(f"{where} must be (across, along, depth) in mm, got {package!r}") from None
    if len(sizes) != 3 or not all(0.0 < v <= MAX_LENGTH_MM for v in sizes):
        raise InputError(
            f"{where} must be three lengths (across, along, depth) in (0, {MAX_LENGTH_MM:g}] mm, "
            f"got {package!r}"
        )


def sensor_to_dict(model):
    """A sensor model's parameters as a JSON-ready dict.

    Parameters
    ----------
    model : reflector_opt.model._sensors.SensorModel

    Returns
    -------
    dict
        One key per parameter; ``range_mm`` a list, ``measured_curve`` and ``package_mm``
        left out when the model has none.
    """
    d = asdict(model)
    d["range_mm"] = list(model.range_mm)
    d["package_mm"] = None if model.package_mm is None else list(model.package_mm)
    d["measured_curve"] = None if model.measured_curve is None else model.measured_curve.to_dict()
    return {key: value for key, value in d.items() if value is not None}


class CurveTable(schema.Table):
    """A measured flat-target curve (:class:`~reflector_opt.model._flat_target.MeasuredCurve`)."""

    distance_mm: Annotated[list[_Distance], Meta(min_length=4, max_length=MAX_CURVE_POINTS)]
    volts: Annotated[list[_Voltage], Meta(min_length=4, max_length=MAX_CURVE_POINTS)]
    reflectance: Annotated[float, Meta(gt=0, le=1, description="ρ of the target")] = 0.9
    specular_fraction: Annotated[float, Meta(ge=0, le=1, description="f of the target")] = 1.0


class SensorDocument(schema.Table):
    """The declared schema of a sensor model's dict form (``sensor_models`` of a design)."""

    name: str
    range_mm: Annotated[list[_Distance], Meta(min_length=2, max_length=2, description="mm")]
    emitter_detector_mm: _Length
    source_radius_mm: _Length
    divergence_deg: Annotated[float, Meta(gt=0, lt=90, description="1/e half-angle, degrees")]
    detector_area_mm2: Annotated[float, Meta(gt=0, le=MAX_LENGTH_MM**2, description="mm²")]
    supply_v: Annotated[float, Meta(gt=0, le=1e3, description="V")]
    led_forward_v: _Voltage
    led_resistor_ohm: _Resistance
    load_resistor_ohm: _Resistance
    saturation_v: _Voltage
    current_gain: Annotated[float, Meta(gt=0, le=1e6)]
    dark_current_a: Annotated[float, Meta(ge=0, le=1, description="A")] = 0.0
    measured_curve: CurveTable | None = None
    package_mm: (
        Annotated[
            list[_Length],
            Meta(
                min_length=3,
                max_length=3,
                description="package across, along the emitter-detector line and deep, mm",
            ),
        ]
        | None
    ) = None


def sensor_from_dict(cls, data, where="sensor model"):
    """Build a sensor model from :func:`sensor_to_dict` output, checked against the schema.

    Parameters
    ----------
    cls : type
        The sensor model class (:class:`~reflector_opt.model._sensors.SensorModel`).
    data : dict
        The dict form, checked against :class:`SensorDocument`.
    where : str, optional
        Where ``data`` comes from, to prefix error messages.

    Returns
    -------
    cls instance
        Raises :class:`~reflector_opt.util._errors.InputError` for a key that is unknown,
        missing, not of its type or out of its range, or for parameters that do not fit
        together (:func:`check_sensor`).
    """
    document = schema.convert(data, SensorDocument, where=where)
    values = msgspec.structs.asdict(document)
    values["range_mm"] = tuple(document.range_mm)
    if document.package_mm is not None:
        values["package_mm"] = tuple(document.package_mm)
    curve = document.measured_curve
    if curve is not None:
        values["measured_curve"] = MeasuredCurve(
            distance_mm=tuple(curve.distance_mm),
            volts=tuple(curve.volts),
            reflectance=curve.reflectance,
            specular_fraction=curve.specular_fraction,
        )
    return cls(**values)


def json_schema():
    """The JSON Schema of a sensor model (``docs/sensor-model.schema.json``).

    Returns
    -------
    dict
    """
    return schema.json_schema(SensorDocument, "sensor model (design.json sensor_models)")
