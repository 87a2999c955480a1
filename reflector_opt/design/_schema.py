"""The declared schema of ``design.json`` (format ``reflector-opt/design@1``), with msgspec.

:class:`DesignDocument` states every block and key of the document with its type, unit and
physical range (docs/conventions.md#limits). :func:`check_document` validates a parsed
document against it (:func:`reflector_opt.util._schema.convert`: the first failure becomes an
:class:`~reflector_opt.util._errors.InputError` naming the key, the range and the unit);
:func:`json_schema` gives the JSON Schema published as ``docs/design.schema.json``. What the
schema cannot state — relations between keys (min below max, a unit's parts fitting
together) — is checked by the :class:`~reflector_opt.design._design.Design` itself.
"""

from typing import Annotated, Any, Literal

import msgspec
from msgspec import Meta

from reflector_opt.design._validation import DIRECTION_BOUND
from reflector_opt.model._sensor_file import SensorDocument
from reflector_opt.model._surface import DEFAULT_MATERIAL, MATERIALS
from reflector_opt.util import _schema as schema
from reflector_opt.util._limits import MAX_ANGLE_DEG, MAX_LENGTH_MM, MAX_SEGMENT_UNITS

FORMAT = "reflector-opt/design@1"

Coordinate = Annotated[
    float, Meta(ge=-MAX_LENGTH_MM, le=MAX_LENGTH_MM, description="a coordinate, mm")
]
Length = Annotated[float, Meta(gt=0, le=MAX_LENGTH_MM, description="a length, mm")]
Point = Annotated[list[Coordinate], Meta(min_length=3, max_length=3, description="x, y, z in mm")]
Component = Annotated[float, Meta(ge=-DIRECTION_BOUND, le=DIRECTION_BOUND)]
Direction = Annotated[
    list[Component], Meta(min_length=3, max_length=3, description="a direction (any length)")
]
Angle = Annotated[float, Meta(gt=-MAX_ANGLE_DEG, lt=MAX_ANGLE_DEG, description="an angle, degrees")]
AngleRange = Annotated[
    list[Angle], Meta(min_length=2, max_length=2, description="[min, max], degrees")
]
Fraction = Annotated[float, Meta(ge=0, le=1)]


class ReflectorBlock(schema.Table):
    """The convex spherical reflector."""

    radius_mm: Annotated[Length, Meta(description="sphere radius R, mm")]
    centre_mm: Annotated[Point, Meta(description="sphere centre s0 at the zero pose, mm")]
    inner_radius_mm: Annotated[Length, Meta(description="inner radius of the shell, mm")] = 7.5
    reflectance: Annotated[
        float, Meta(gt=0, le=1, description="total diffuse-plus-specular reflectance ρ")
    ] = MATERIALS[DEFAULT_MATERIAL].reflectance
    specular_fraction: Annotated[
        Fraction, Meta(description="specular fraction f (1 when absent: a mirror)")
    ] = 1.0


class SensorBlock(schema.Table):
    """One sensor on the flexible strip."""

    model: Annotated[str, Meta(description="a sensor preset or a key of sensor_models")]
    position_mm: Annotated[Point, Meta(description="emitter/detector position, mm")]
    axis: Annotated[Direction, Meta(description="optical axis (normalised on reading)")]
    name: str | None = None
    detector_direction: Direction = msgspec.field(default_factory=lambda: [0.0, 0.0, 1.0])


class WorkspaceBlock(schema.Table):
    """The poses one unit must sense."""

    pitch_deg: Annotated[AngleRange, Meta(description="pitch γ range, degrees")]
    roll_deg: Annotated[AngleRange, Meta(description="roll α range, degrees")]
    step_deg: Annotated[
        float, Meta(gt=0, lt=2 * MAX_ANGLE_DEG, description="calibration grid step, degrees")
    ] = 0.1


class JointBlock(schema.Table):
    """A joint the user describes: a spherical plain bearing's figures."""

    bore_mm: Annotated[Length, Meta(description="bore d, mm")]
    outer_diameter_mm: Annotated[Length, Meta(description="outside diameter D, mm")]
    inner_width_mm: Annotated[Length, Meta(description="inner ring's width B, mm")]
    outer_width_mm: Annotated[Length, Meta(description="outer ring's width C, mm")]
    ball_diameter_mm: Annotated[Length, Meta(description="ball diameter dk, mm")]
    clearance_um: Annotated[float, Meta(ge=0, le=500, description="radial internal clearance, µm")]
    stop_deg: (
        Annotated[
            float,
            Meta(gt=0, lt=90, description="tilt stop, degrees; absent: acos(d/dk) - asin(C/dk)"),
        ]
        | None
    ) = None


class MechanicsBlock(schema.Table):
    """Mechanical envelope of one unit."""

    unit_diameter_mm: Length = 22.0
    unit_height_mm: Length = 12.0
    bearing_bore_mm: Length = 6.0
    bearing_od_mm: Length = 14.0
    link_length_mm: Length = 18.0
    n_units: Annotated[int, Meta(ge=1, le=MAX_SEGMENT_UNITS, description="units in a segment")] = 4
    min_wall_mm: Length = 0.8
    bearing: (
        Annotated[
            str,
            Meta(
                description="a bearing of the bearing catalogue (its bore and outside diameter "
                "replace bearing_bore_mm and bearing_od_mm; its tilt limits the workspace)",
            ),
        ]
        | None
    ) = None
    joint: (
        Annotated[
            JointBlock,
            Meta(description="a joint described instead of a bearing named (not with bearing)"),
        ]
        | msgspec.UnsetType
    ) = msgspec.UNSET


class NoiseBlock(schema.Table):
    """Read-out noise and the ADC."""

    sigma_v: Annotated[float, Meta(ge=0, le=1e3, description="voltage noise σ, V")] = 0.002
    adc_bits: Annotated[int, Meta(ge=1, le=32, description="ADC resolution, bits")] = 12
    vref: Annotated[float, Meta(gt=0, le=1e3, description="ADC reference, V")] = 3.3


class DesignDocument(schema.Table):
    """A ``design.json`` document: lengths in mm, angles in degrees, voltages in volts."""

    reflector: ReflectorBlock
    sensors: Annotated[list[SensorBlock], Meta(description="the sensors (a unit needs two)")]
    workspace: WorkspaceBlock
    format: Literal["reflector-opt/design@1"] = FORMAT
    mechanics: MechanicsBlock = msgspec.field(default_factory=MechanicsBlock)
    noise: NoiseBlock = msgspec.field(default_factory=NoiseBlock)
    sensor_models: Annotated[
        dict[str, SensorDocument], Meta(description="sensor parts defined by the design")
    ] = msgspec.field(default_factory=dict)
    predicted: Annotated[
        dict[str, Any], Meta(description="figures predicted when the design was made")
    ] = msgspec.field(default_factory=dict)
    correction: Annotated[
        dict[str, Any],
        Meta(
            description="the print correction this geometry carries: what was changed, by "
            "how much, from which identified units (docs/print-loop.md)"
        ),
    ] = msgspec.field(default_factory=dict)


def json_schema():
    """The JSON Schema of ``design.json``, generated from :class:`DesignDocument`.

    Returns
    -------
    dict
    """
    return schema.json_schema(DesignDocument, f"design.json ({FORMAT})")


def check_document(data):
    """Validate a parsed ``design.json`` document against the schema.

    Parameters
    ----------
    data : object
        The parsed JSON.

    Returns
    -------
    DesignDocument
        With the defaults filled in.

    Raises
    ------
    InputError
        The first key that breaks the schema, e.g. ``reflector.radius_mm: expected a number
        > 0 and ≤ 1000 mm, got 2000``.
    """
    return schema.convert(data, DesignDocument)
