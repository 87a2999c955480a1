"""Operating conditions: what a unit meets in use beyond white noise (``[conditions]`` TOML).

The conditions file (format ``reflector-opt/conditions@1``, JSON Schema
``docs/conditions.schema.json``) describes the world a calibrated unit is used in, relative to
the bench it was calibrated on. Every key is optional; the defaults describe a bench at room
temperature (docs/conditions.md):

.. code-block:: toml

    [conditions]
    temperature_range_k = 2.0          # ± junction temperature change from calibration, K
    temperature_compensated = false    # the calibration is temperature-aware (a thermometer)
    thermometer_offset_k = 0.5         # the thermometer's error against the junctions, K
    thermometer_lag_s = 30.0           # its lag behind the junctions, s ...
    temperature_rate_k_per_min = 0.5   # ... while the temperature changes at this rate
    strip_gradient_k = 0.5             # temperature difference along the sensor strip, K
    calibration_temperature_c = 25.0   # the calibration temperature, °C
    ambient_mv = 1.0                   # change of ambient light at the output, mV
    ambient_flicker_mv = 0.5           # mains flicker at the output, peak mV
    flicker_hz = 100.0                 # twice the mains frequency (100 or 120 Hz)
    drive = "dc"                       # "dc", "multiplexed" or "modulated"
    sample_rate_hz = 10000.0           # ADC conversions per second
    neighbour_crosstalk = 0.005        # share of a neighbouring unit's photocurrent seen
    angular_speed_deg_s = 5.0          # speed of the calibration motion, °/s
    reference_latency_ms = 2.0         # delay of the angle reference, ms
    angle_reference = "imu-lpms-b"     # the calibration's angle reference (ANGLE_REFERENCES)
    reference_zero_deg = [0.1, 0.1]    # its zero offset, pitch and roll, ° (default: its class)
    reference_twist_deg = 0.1          # twist of the reference's axes about the backbone, °
    joint_clearance_um = 68.0          # the bearing's radial internal clearance, µm
    tendon_preload_n = 1.0             # the tendons' preload on the joint, N (0: a free joint)
    load_reverses = false              # the joint's load changes direction in use
    joint_hysteresis_deg = 0.0         # the joint's hysteresis, full width, °
    supply_change_mv = 10.0            # change of the supply from calibration to use, mV
    adc_reference = "fixed"            # the ADC's reference: "fixed" or "ratiometric"
    hours_since_calibration = 0.0      # the LEDs' hours of use since calibration (ageing), h
    cold_start = false                 # read from switch-on, before the LEDs warm up
    resin_cte_ppm_per_k = 145.1        # thermal expansion of the printed reflector, ppm/K
    strip_cte_ppm_per_k = 13.0         # in-plane thermal expansion of the sensor strip, ppm/K

Every default is a figure with its kind and source (:data:`DEFAULT_BASIS`, docs/conditions.md);
an assumed one takes the unfavourable end of its plausible range.
A :class:`Conditions` is that table, checked: types and ranges by the schema (one line naming
the key), and the values that betray a wrong unit (kelvin for a range of kelvin, volts where
millivolts are asked, radians where degrees) refused with the unit named.
"""

from typing import Annotated, Literal

import msgspec
import numpy as np
from msgspec import Meta

from reflector_opt.util import _schema as schema
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import read_config

FORMAT = "reflector-opt/conditions@1"

#: The kinds of angle reference a unit is calibrated against: each one's accuracy class, static
#: (at rest) and dynamic (in motion), degrees per angle, as figures (docs/conditions.md, "The
#: angle reference"). ``"stated"``: the conditions' own ``reference_zero_deg``.
ANGLE_REFERENCES = {
    "imu-lpms-b": {
        "static_deg": {
            "value": 1.0,
            "kind": "assumed",
            "range": [0.5, 1.0],
            "source": "LP-Research LPMS-B (first generation), the paper's reference: its manual "
            "(LPMS-B Reference Manual 1.1.0, 2013) not read; the class of its successor's "
            "published < 0.5° (LPMS-B2 Hardware Manual 1.0, 2020, Table 4-1) to twice it, "
            "1.0°, the unfavourable end",
        },
        "dynamic_deg": {
            "value": 3.0,
            "kind": "assumed",
            "range": [2.0, 3.0],
            "source": "LPMS-B not read (see static_deg); its successor's published < 2° RMS "
            "(LPMS-B2 Hardware Manual 1.0, Table 4-1) to 3° RMS, the unfavourable end",
        },
    },
    "imu-lpms-b2": {
        "static_deg": {
            "value": 0.5,
            "kind": "published",
            "source": "LP-Research LPMS-B2 Hardware Manual 1.0 (2020-03-10), Table 4-1 "
            "'Overall parameters': orientation accuracy < 0.5° static (resolution < 0.01°)",
        },
        "dynamic_deg": {
            "value": 2.0,
            "kind": "published",
            "source": "LPMS-B2 Hardware Manual 1.0, Table 4-1: < 2° RMS dynamic",
        },
    },
    "encoder": {
        "static_deg": {
            "value": 5.49 / 3600.0,
            "kind": "published",
            "source": "a rig of optical rotary encoders on the two axes: Renishaw RESOLUTE "
            "with RESA ring, ±0.52-5.49 arc seconds system accuracy (renishaw.com product "
            "page of RESOLUTE ETR with RESA), 5.49″ the unfavourable end; the rig's own "
            "zero against the unit is not in it (state it as reference_zero_deg)",
        },
    },
    "stated": {},
}

#: The angle reference's distance from the joint it calibrates, m: an IMU on the segment's
#: tip, four units of 25 mm above the lowest joint (the paper's Fig. 6), the unfavourable end
#: (more acceleration for a speed) of one to four units.
REFERENCE_LEVER_M = {
    "value": 0.1,
    "kind": "assumed",
    "range": [0.025, 0.1],
    "source": "the paper's calibration rig (Osman et al. 2024, Fig. 6): the IMU on the tip "
    "unit, one to four units of about 25 mm above the calibrated joint",
}
#: Standard gravity, m/s² (ISO 80000-3).
STANDARD_GRAVITY_M_S2 = 9.80665

_Kelvin = Annotated[float, Meta(ge=0, le=100, description="K")]
_Millivolts = Annotated[float, Meta(ge=0, le=3300, description="mV at the sensor output")]
_Degrees = Annotated[float, Meta(ge=-20, le=20, description="degrees")]


class Conditions(schema.Table, frozen=True):
    """The operating conditions of a unit, relative to its calibration.

    Attributes
    ----------
    temperature_range_k : float
        The junction temperature in use lies within ± this of the calibration's, K.
    temperature_compensated : bool
        The calibration is temperature-aware (readings with a thermometer's temperature, at
        several temperatures): what stays of the temperature term is the thermometer's
        error against the junctions, the strip's gradient and the response's curvature
        (docs/conditions.md, "Temperature compensation").
    thermometer_offset_k : float
        The thermometer's error against the junctions' temperature, K.
    thermometer_lag_s : float
        The thermometer's lag behind the junctions, s.
    temperature_rate_k_per_min : float
        The rate the temperature changes at in use, K/min (with the lag, an error of
        lag · rate).
    strip_gradient_k : float
        The temperature difference between the strip's first and last sensor, K.
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
    angle_reference : str
        The kind of angle reference the unit is calibrated against, one of
        :data:`ANGLE_REFERENCES`: its accuracy class is the zero offset the calibration learns
        (:meth:`reference_zero`), unless ``reference_zero_deg`` is given.
    reference_zero_deg : list of float or None
        Zero offset of the angle reference, (pitch, roll), degrees; given, it wins over the
        ``angle_reference``'s class; None: the class (required for ``"stated"``).
    reference_twist_deg : float
        Rotation of the reference's pitch and roll axes about the backbone, degrees.
    joint_clearance_um : float or None
        Radial internal clearance of the joint's bearing, µm; None: the upper end of the
        normal class of the design's bearing (ISO 12240-1; the bearing catalogue).
    tendon_preload_n : float
        The tendons' preload on the joint, N. Above zero the ball is seated against its ring
        in a repeatable place that the calibration learns; 0 is a free joint.
    load_reverses : bool
        Whether the joint's load changes direction in use (a robot lying sideways, a
        contact): the ball then crosses its clearance, which no calibration learns.
    joint_hysteresis_deg : float
        Full width of the joint's angular hysteresis, degrees.
    supply_change_mv : float
        Change of the supply voltage Vcc between calibration and use, mV.
    adc_reference : str
        ``"fixed"`` (the ADC reads volts against its own reference) or ``"ratiometric"``
        (against the sensors' supply).
    hours_since_calibration : float
        Hours the LEDs have been lit since the calibration, h (their output ages).
    cold_start : bool
        Readings from switch-on, before the LED junctions reach their steady temperature.
    resin_cte_ppm_per_k : float
        Linear thermal expansion coefficient of the printed reflector, ppm/K: its radius and
        its centre's offset from the joint scale by 1 + α ΔT.
    strip_cte_ppm_per_k : float
        In-plane thermal expansion coefficient of the sensor strip, ppm/K: the sensors'
        positions scale by 1 + α ΔT about the joint (give the body's if the body places them).
    """

    temperature_range_k: _Kelvin = 2.0
    temperature_compensated: bool = False
    thermometer_offset_k: Annotated[float, Meta(ge=0, le=20, description="K")] = 0.5
    thermometer_lag_s: Annotated[float, Meta(ge=0, le=3600, description="s")] = 30.0
    temperature_rate_k_per_min: Annotated[float, Meta(ge=0, le=60, description="K/min")] = 0.5
    strip_gradient_k: Annotated[float, Meta(ge=0, le=20, description="K")] = 0.5
    calibration_temperature_c: Annotated[float, Meta(ge=-40, le=100, description="°C")] = 25.0
    ambient_mv: _Millivolts = 1.0
    ambient_flicker_mv: _Millivolts = 0.5
    flicker_hz: Annotated[float, Meta(gt=0, le=10000, description="Hz")] = 100.0
    drive: Literal["dc", "multiplexed", "modulated"] = "dc"
    sample_rate_hz: Annotated[float, Meta(ge=10, le=1e7, description="Hz")] = 10000.0
    neighbour_crosstalk: Annotated[float, Meta(ge=0, le=0.2, description="share")] = 0.005
    angular_speed_deg_s: Annotated[float, Meta(ge=0, le=1000, description="°/s")] = 5.0
    reference_latency_ms: Annotated[float, Meta(ge=0, le=1000, description="ms")] = 2.0
    angle_reference: Literal[tuple(ANGLE_REFERENCES)] = "imu-lpms-b"
    reference_zero_deg: Annotated[list[_Degrees], Meta(min_length=2, max_length=2)] | None = None
    reference_twist_deg: _Degrees = 0.1
    joint_clearance_um: Annotated[float, Meta(ge=0, le=500, description="µm")] | None = None
    tendon_preload_n: Annotated[float, Meta(ge=0, le=1000, description="N")] = 1.0
    load_reverses: bool = False
    joint_hysteresis_deg: Annotated[float, Meta(ge=0, le=10, description="degrees")] = 0.0
    supply_change_mv: Annotated[float, Meta(ge=0, le=1000, description="mV")] = 10.0
    adc_reference: Literal["fixed", "ratiometric"] = "fixed"
    hours_since_calibration: Annotated[float, Meta(ge=0, le=1e6, description="h")] = 0.0
    cold_start: bool = False
    resin_cte_ppm_per_k: Annotated[float, Meta(ge=0, le=500, description="ppm/K")] = 145.1
    strip_cte_ppm_per_k: Annotated[float, Meta(ge=0, le=500, description="ppm/K")] = 13.0

    @classmethod
    def quiet(cls):
        """Every condition at zero: a unit in use meets nothing but its white noise (the
        budget's total is then the Cramér–Rao floor, the optimiser's objective the white-noise
        one)."""
        return cls(
            temperature_range_k=0.0,
            thermometer_offset_k=0.0,
            temperature_rate_k_per_min=0.0,
            strip_gradient_k=0.0,
            ambient_mv=0.0,
            ambient_flicker_mv=0.0,
            neighbour_crosstalk=0.0,
            angular_speed_deg_s=0.0,
            reference_zero_deg=[0.0, 0.0],
            reference_twist_deg=0.0,
            joint_clearance_um=0.0,
            supply_change_mv=0.0,
        )

    def reference_figure(self):
        """The figure of the angle reference's class the calibration learns, or None when the
        zero is stated.

        An inertial reference reads tilt from gravity; motion adds an acceleration a that it
        reads as a tilt error of about a/g. Its static class holds while a/g stays below that
        class; its dynamic class (general motion) once the calibration's own motion, a = ω²·L
        at ``angular_speed_deg_s`` ω on the lever arm L of :data:`REFERENCE_LEVER_M`, reaches
        it: 75 °/s for a 1° class on 0.1 m. Slower calibrations, as the paper's, learn the
        static class.

        Returns
        -------
        dict or None
            ``{"name", "value", "kind", "source", …}``, degrees.
        """
        if self.reference_zero_deg is not None:
            return None
        figures = ANGLE_REFERENCES[self.angle_reference]
        omega = np.deg2rad(self.angular_speed_deg_s)
        motion_rad = omega**2 * REFERENCE_LEVER_M["value"] / STANDARD_GRAVITY_M_S2
        moving = "dynamic_deg" in figures and motion_rad >= np.deg2rad(
            figures["static_deg"]["value"]
        )
        name = "dynamic_deg" if moving else "static_deg"
        return {"name": f"{self.angle_reference}: {name}", **figures[name]}

    def reference_zero(self):
        """The angle reference's zero offset the calibration learns, (pitch, roll), degrees.

        ``reference_zero_deg`` where given; else the class of ``angle_reference``
        (:meth:`reference_figure`) on each angle: a reference whose readings carry a bias b
        and a random error of σ teaches a calibration of p coefficients fitted at N poses b and
        about σ·sqrt(p/N) of the noise, so for a class a (abs(b) + σ within a, or b² + σ² = a²)
        the error it leaves is largest, a, when all of a is bias (docs/conditions.md).

        Returns
        -------
        tuple of float
        """
        if self.reference_zero_deg is not None:
            return tuple(float(z) for z in self.reference_zero_deg)
        value = float(self.reference_figure()["value"])
        return (value, value)

    def replace(self, **changes):
        """A copy with some fields changed, checked as a file's would be."""
        return parse_conditions({"conditions": {**self.to_dict(), **changes}})

    def to_dict(self):
        """The ``[conditions]`` table as plain Python values (the ``--json`` block)."""
        table = msgspec.structs.asdict(self)
        if table["reference_zero_deg"] is not None:
            table["reference_zero_deg"] = list(table["reference_zero_deg"])  # a copy
        return table


class ConditionsDocument(schema.Table):
    """A conditions file: the format line and the ``[conditions]`` table."""

    format: Literal["reflector-opt/conditions@1"] = FORMAT
    conditions: Conditions = msgspec.field(default_factory=Conditions)


#: The kind and source of each default that is a physical figure (docs/conditions.md).
DEFAULT_BASIS = {
    "joint_clearance_um": (
        "published",
        "the upper end of the normal class of the design's bearing (ISO 12240-1), from the "
        "bearing catalogue (reflector_opt/data/bearing_catalogue.toml), where each row's "
        "kind is stated",
    ),
    "tendon_preload_n": (
        "derived",
        "the tension that holds a pose against the weight of the distal units: three 22 mm "
        "units of about 5 g (0.15 N) at up to 3 unit lengths (66 mm) from the joint, held by "
        "a tendon 8 mm off the axis, need 0.15 N · 66/8 ≈ 1.2 N; 1 N is the round figure",
    ),
    "supply_change_mv": (
        "assumed",
        "a 3.3 V regulator's line and load regulation and drift between calibration and "
        "use: 1-10 mV plausible; 10 mV, the unfavourable end",
    ),
    "adc_reference": ("assumed", "a fixed reference, the unfavourable one of the two"),
    "temperature_range_k": ("assumed", "a bench at room temperature, ±2 K"),
    "thermometer_offset_k": (
        "assumed",
        "a thermometer on the strip beside the sensors, against their junctions: a digital "
        "sensor's ±0.1-0.5 K and the path from junction to thermometer: 0.5 K, the "
        "unfavourable end",
    ),
    "thermometer_lag_s": (
        "assumed",
        "a thermometer a few mm from the junctions through the board: 5-30 s; 30 s, the "
        "unfavourable end",
    ),
    "temperature_rate_k_per_min": (
        "assumed",
        "a unit warming up in use or a lab's air: 0.1-0.5 K/min; 0.5, the unfavourable end",
    ),
    "strip_gradient_k": (
        "assumed",
        "the sensors of one unit a few mm apart on one board: 0.1-0.5 K; 0.5, the unfavourable end",
    ),
    "angle_reference": (
        "published",
        "the paper's reference, an LP-Research LPMS-B IMU on the top unit (Osman et al. "
        "2024, section 2); its class in ANGLE_REFERENCES, where each figure's kind is stated",
    ),
    "resin_cte_ppm_per_k": (
        "assumed",
        "the paper's white SLA resin: not found for Formlabs' standard resins; Formlabs "
        "Durable 117.0 green, 145.1 post-cured µm/m/°C (23-50 °C, ASTM E831; Formlabs "
        "material properties, Durable FLDUCL01, rev. 01 04.18.17), rigid acrylate resins "
        "about 60-100: 60-145.1 ppm/K plausible, 145.1 the unfavourable end",
    ),
    "strip_cte_ppm_per_k": (
        "assumed",
        "the strip's laminate in-plane: FR-4 13-14 ppm/K below Tg (Isola 370HR data sheet, "
        "X/Y), copper 17.7, polyimide 20 (DuPont Kapton HN, -14 to 38 °C, ASTM D-696): 13-20 "
        "ppm/K; 13, the unfavourable end (the largest difference from the resin)",
    ),
}


def _check_units(conditions):
    """Refuse values whose size betrays a wrong unit; one line naming the key."""
    zero = conditions.reference_zero_deg or ()
    if conditions.angle_reference == "stated" and not zero:
        raise InputError(
            'conditions.reference_zero_deg: angle_reference = "stated" needs the reference\'s '
            "zero offset given, [pitch, roll] degrees"
        )
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
    if 0.0 < conditions.supply_change_mv < 0.1:
        raise InputError(
            f"conditions.supply_change_mv: {conditions.supply_change_mv} mV (below 0.1 mV) "
            "looks like volts; give millivolts"
        )
    if conditions.thermometer_lag_s > 600.0:
        raise InputError(
            f"conditions.thermometer_lag_s: {conditions.thermometer_lag_s} s (over 10 min) "
            "looks like milliseconds; give seconds"
        )
    per_kelvin = (
        "ppm/K (below 0.01) looks like a coefficient per kelvin; give parts per million per kelvin"
    )
    volts = "mV (below 10 µV at the output) looks like volts; give millivolts"
    for key, least, said in (
        ("joint_clearance_um", 0.5, "µm (below 0.5 µm) looks like millimetres; give micrometres"),
        ("resin_cte_ppm_per_k", 0.01, per_kelvin),
        ("strip_cte_ppm_per_k", 0.01, per_kelvin),
        ("ambient_mv", 0.01, volts),
        ("ambient_flicker_mv", 0.01, volts),
    ):
        value = getattr(conditions, key)
        if value is not None and 0.0 < value < least:
            raise InputError(f"conditions.{key}: {value} {said}")


def parse_conditions(data):
    """Build :class:`Conditions` from a parsed TOML document (``[conditions]`` table).

    Parameters
    ----------
    data : dict
        As returned by :func:`tomllib.loads`.

    Returns
    -------
    Conditions
        Raises :class:`~reflector_opt.util._errors.InputError` naming the key at fault.
    """
    table = data.get("conditions") if isinstance(data, dict) else None
    if isinstance(table, dict) and "joint_play_um" in table:
        raise InputError(
            "conditions.joint_play_um: no longer read; give the bearing's radial internal "
            "clearance as joint_clearance_um (µm; the play was half of it), with "
            'tendon_preload_n and load_reverses (docs/conditions.md, "The joint")'
        )
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
