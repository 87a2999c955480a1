"""Operating conditions: what a unit meets in use beyond white noise (``[conditions]`` TOML).

The conditions file (format ``reflector-opt/conditions@1``, JSON Schema
``docs/conditions.schema.json``) describes the world a calibrated unit is used in, relative to
the bench it was calibrated on. Every key is optional; the defaults describe a bench at room
temperature (docs/conditions.md):

.. code-block:: toml

    [conditions]
    temperature_range_k = 2.0          # ± junction temperature change from calibration, K
    calibration_temperature_c = 25.0   # the calibration temperature, °C
    ambient_mv = 1.0                   # change of ambient light at the output, mV
    ambient_flicker_mv = 0.5           # mains flicker at the output, peak mV
    flicker_hz = 100.0                 # twice the mains frequency (100 or 120 Hz)
    drive = "dc"                       # "dc", "multiplexed" or "modulated"
    sample_rate_hz = 10000.0           # ADC conversions per second
    neighbour_crosstalk = 0.005        # share of a neighbouring unit's photocurrent seen
    angular_speed_deg_s = 5.0          # speed of the calibration motion, °/s
    reference_latency_ms = 2.0         # delay of the angle reference, ms
    reference_zero_deg = [0.1, 0.1]    # the reference's zero offset, pitch and roll, °
    reference_twist_deg = 0.1          # twist of the reference's axes about the backbone, °
    joint_play_um = 5.0                # radial play of the joint, µm
    joint_hysteresis_deg = 0.0         # the joint's hysteresis, full width, °
    cold_start = false                 # read from switch-on, before the LEDs warm up

A :class:`Conditions` is that table, checked: types and ranges by the schema (one line naming
the key), and the values that betray a wrong unit (kelvin for a range of kelvin, volts where
millivolts are asked, radians where degrees) refused with the unit named.
"""

from __future__ import annotations

from typing import Annotated, Literal

import msgspec
from msgspec import Meta

from reflector_opt.model.drive import DRIVES
from reflector_opt.util import schema
from reflector_opt.util.errors import InputError
from reflector_opt.util.fileio import read_config

__all__ = [
    "DRIVES",
    "FORMAT",
    "Conditions",
    "ConditionsDocument",
    "as_conditions",
    "json_schema",
    "load_conditions",
    "parse_conditions",
]

FORMAT = "reflector-opt/conditions@1"

_Kelvin = Annotated[float, Meta(ge=0, le=100, description="K")]
_Millivolts = Annotated[float, Meta(ge=0, le=3300, description="mV at the sensor output")]
_Degrees = Annotated[float, Meta(ge=-20, le=20, description="degrees")]


class Conditions(schema.Table, frozen=True):
    """The operating conditions of a unit, relative to its calibration.

    Attributes
    ----------
    temperature_range_k : float
        The junction temperature in use lies within ± this of the calibration's, K.
    calibration_temperature_c : float
        The calibration temperature, °C (the dark current's reference).
    ambient_mv : float
        Change of the ambient light between calibration and use, as the drop it gives at the
        output, mV.
    ambient_flicker_mv : float
        Peak amplitude of the mains flicker of the ambient light at the output, mV.
    flicker_hz : float
        Frequency of the flicker, Hz (twice the mains frequency).
    drive : str
        ``"dc"`` (every LED on), ``"multiplexed"`` (one LED at a time) or ``"modulated"``
        (one LED at a time, each read on and off and differenced).
    sample_rate_hz : float
        ADC conversions per second, shared by the sensors read in turn.
    neighbour_crosstalk : float
        Share of a neighbouring unit's photocurrent that reaches each detector through the
        body when both LEDs are on (0–0.2).
    angular_speed_deg_s : float
        Speed of the calibration motion, °/s (with the latency, a lag of the reference).
    reference_latency_ms : float
        Delay of the angle reference behind the sensors, ms.
    reference_zero_deg : list of float
        Zero offset of the angle reference, (pitch, roll), degrees.
    reference_twist_deg : float
        Rotation of the reference's pitch and roll axes about the backbone, degrees.
    joint_play_um : float
        Radial play of the joint: the reflector may shift by up to this, µm.
    joint_hysteresis_deg : float
        Full width of the joint's angular hysteresis, degrees.
    cold_start : bool
        Readings from switch-on, before the LED junctions reach their steady temperature.
    """

    temperature_range_k: _Kelvin = 2.0
    calibration_temperature_c: Annotated[float, Meta(ge=-40, le=100, description="°C")] = 25.0
    ambient_mv: _Millivolts = 1.0
    ambient_flicker_mv: _Millivolts = 0.5
    flicker_hz: Annotated[float, Meta(gt=0, le=10000, description="Hz")] = 100.0
    drive: Literal["dc", "multiplexed", "modulated"] = "dc"
    sample_rate_hz: Annotated[float, Meta(ge=10, le=1e7, description="Hz")] = 10000.0
    neighbour_crosstalk: Annotated[float, Meta(ge=0, le=0.2, description="share")] = 0.005
    angular_speed_deg_s: Annotated[float, Meta(ge=0, le=1000, description="°/s")] = 5.0
    reference_latency_ms: Annotated[float, Meta(ge=0, le=1000, description="ms")] = 2.0
    reference_zero_deg: Annotated[list[_Degrees], Meta(min_length=2, max_length=2)] = msgspec.field(
        default_factory=lambda: [0.1, 0.1]
    )
    reference_twist_deg: _Degrees = 0.1
    joint_play_um: Annotated[float, Meta(ge=0, le=500, description="µm")] = 5.0
    joint_hysteresis_deg: Annotated[float, Meta(ge=0, le=10, description="degrees")] = 0.0
    cold_start: bool = False

    @classmethod
    def quiet(cls):
        """Every condition at zero: a unit in use meets nothing but its white noise (the
        budget's total is then the Cramér–Rao floor, the optimiser's objective the white-noise
        one)."""
        return cls(
            temperature_range_k=0.0,
            ambient_mv=0.0,
            ambient_flicker_mv=0.0,
            neighbour_crosstalk=0.0,
            angular_speed_deg_s=0.0,
            reference_zero_deg=[0.0, 0.0],
            reference_twist_deg=0.0,
            joint_play_um=0.0,
        )

    def replace(self, **changes):
        """A copy with some fields changed, checked as a file's would be."""
        return parse_conditions({"conditions": {**self.to_dict(), **changes}})

    def to_dict(self):
        """The ``[conditions]`` table as plain Python values (the ``--json`` block)."""
        table = msgspec.structs.asdict(self)
        table["reference_zero_deg"] = list(table["reference_zero_deg"])  # a copy
        return table


class ConditionsDocument(schema.Table):
    """A conditions file: the format line and the ``[conditions]`` table."""

    format: Literal["reflector-opt/conditions@1"] = FORMAT
    conditions: Conditions = msgspec.field(default_factory=Conditions)


def _check_units(conditions):
    """Refuse values whose size betrays a wrong unit; one line naming the key."""
    zero = conditions.reference_zero_deg
    if any(0.0 < abs(z) < 0.005 for z in zero) and all(abs(z) < 0.005 for z in zero):
        raise InputError(
            f"conditions.reference_zero_deg: {list(zero)} looks like radians of a tiny angle; "
            "give degrees"
        )
    if conditions.temperature_range_k > 60.0:
        raise InputError(
            f"conditions.temperature_range_k: {conditions.temperature_range_k} K is a range "
            "of ± kelvin around the calibration temperature, not an absolute temperature"
        )
    for key in ("ambient_mv", "ambient_flicker_mv"):
        if 0.0 < getattr(conditions, key) < 0.01:
            raise InputError(
                f"conditions.{key}: {getattr(conditions, key)} mV (below 10 µV at the output) "
                "looks like volts; give millivolts"
            )


def parse_conditions(data):
    """Build :class:`Conditions` from a parsed TOML document (``[conditions]`` table).

    Parameters
    ----------
    data : dict
        As returned by :func:`tomllib.loads`.

    Returns
    -------
    Conditions
        Raises :class:`~reflector_opt.util.errors.InputError` naming the key at fault.
    """
    document = schema.convert(data, ConditionsDocument, toml=True)
    _check_units(document.conditions)
    return document.conditions


def load_conditions(path):
    """Read and check a conditions file.

    Parameters
    ----------
    path : str or pathlib.Path
        A TOML file with a ``[conditions]`` table.

    Returns
    -------
    Conditions
    """
    return read_config(path, parse_conditions)


def as_conditions(conditions):
    """Operating conditions from a :class:`Conditions`, its TOML file, or None (kept None).

    Parameters
    ----------
    conditions : Conditions, str, pathlib.Path or None

    Returns
    -------
    Conditions or None
    """
    if conditions is None or isinstance(conditions, Conditions):
        return conditions
    return load_conditions(conditions)


def json_schema():
    """The JSON Schema of the conditions file, published as ``docs/conditions.schema.json``.

    Returns
    -------
    dict
    """
    return schema.json_schema(ConditionsDocument, "reflector-opt operating conditions")
