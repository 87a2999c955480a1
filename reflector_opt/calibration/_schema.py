"""The declared schema of a coefficient file (``reflector-opt/calibration-model@1``).

:class:`ModelDocument` states a fitted Eq5, Eq6 or polynomial model's keys with their type,
unit, range and default, and its optional ``temperature`` block (:class:`Temperature`: a
temperature-compensated calibration, :mod:`~reflector_opt.calibration._temperature`; a file
without it is a plain calibration, as every file written before it existed);
:class:`PhysicalDocument` a fitted physical model's (chosen by ``"model": "physical"``).
:func:`check_model_document` validates a parsed document against the right one. What they
cannot state — the model name and its parameters, the number of coefficients of that model, a
coefficient set whose scaled form overflows — is checked when the model is rebuilt
(:func:`~reflector_opt.calibration._coefficients.model_from_dict`).
"""

import sys
from typing import Annotated, Any, Literal

import msgspec
from msgspec import Meta

from reflector_opt.calibration._physical import PARAMETERS, PhysicalModel
from reflector_opt.calibration._temperature import KELVIN_LIKE_C, MIN_TEMPERATURE_C
from reflector_opt.design._schema import DesignDocument
from reflector_opt.util import _schema as schema
from reflector_opt.util._limits import MAX_ANGLE_DEG

MODEL_FORMAT = "reflector-opt/calibration-model@1"

#: A finite number (a coefficient may be large: it multiplies powers of raw volts).
Finite = Annotated[float, Meta(ge=-sys.float_info.max, le=sys.float_info.max)]
Voltage = Annotated[float, Meta(ge=-1e3, le=1e3, description="V")]
Span = Annotated[float, Meta(gt=0, le=1e3, description="V")]
AngleError = Annotated[float, Meta(ge=0, le=2 * MAX_ANGLE_DEG, description="degrees")]
Samples = Annotated[int, Meta(ge=0, le=10**12, description="samples of the fit")]
Format = Literal["reflector-opt/calibration-model@1"]


class Coefficients(schema.Table):
    """Raw-voltage coefficients of each angle, one per term."""

    pitch_deg: list[Finite]
    roll_deg: list[Finite]


class PerAngle(schema.Table):
    """One figure of each angle, degrees."""

    pitch_deg: AngleError
    roll_deg: AngleError


class Training(schema.Table):
    """Errors on the training data, degrees."""

    rms_deg: PerAngle | None = None
    max_deg: PerAngle | None = None


Celsius = Annotated[float, Meta(ge=MIN_TEMPERATURE_C, le=KELVIN_LIKE_C, description="°C")]
PerKelvin = Annotated[float, Meta(ge=-1, le=1, description="relative change per K, 1/K")]
PerKelvin2 = Annotated[float, Meta(ge=-1, le=1, description="relative change per K², 1/K²")]
VoltsPerKelvin = Annotated[float, Meta(ge=-1, le=1, description="V/K")]
Std = Annotated[float, Meta(ge=0, le=1, description="standard deviation, in the value's unit")]
Pair = Meta(min_length=2, max_length=2)


class Temperature(schema.Table):
    """The thermal parameters of a temperature-compensated calibration, one per sensor."""

    reference_temperature_c: Celsius
    supply_v: Annotated[list[Span], Pair]
    gain_per_k: Annotated[list[PerKelvin], Pair]
    gain_per_k_std: Annotated[list[Std], Pair]
    offset_v_per_k: Annotated[list[VoltsPerKelvin], Pair]
    offset_v_per_k_std: Annotated[list[Std], Pair]
    temperature_range_c: Annotated[list[Celsius], Pair]
    gain_per_k2: Annotated[list[PerKelvin2], Pair] | None = None
    gain_per_k2_std: Annotated[list[Std], Pair] | None = None


class ModelDocument(schema.Table):
    """A fitted Eq5, Eq6 or polynomial model (voltages in volts, angles in degrees)."""

    model: Annotated[str, Meta(description='"eq5", "eq6" or "polyN"')]
    coefficients: Coefficients
    input_centre_v: Annotated[list[Voltage], Meta(min_length=2, max_length=2)]
    input_scale_v: Annotated[list[Span], Meta(min_length=2, max_length=2)]
    format: Format = MODEL_FORMAT
    params: Annotated[
        dict[str, Any], Meta(description="constructor parameters (fit, degree, ...)")
    ] = msgspec.field(default_factory=dict)
    inputs: list[Literal["v1", "v2"]] = msgspec.field(default_factory=lambda: ["v1", "v2"])
    terms: Annotated[list[str], Meta(description="term names (checked)")] | None = None
    n_samples: Samples = 0
    solver: str | None = None
    training: Training = msgspec.field(default_factory=Training)
    huber_threshold_deg: Annotated[list[AngleError], Meta(min_length=2, max_length=2)] | None = None
    temperature: Temperature | None = None


#: The fitted parameters of a physical model, every one required.
Parameters = msgspec.defstruct(
    "Parameters",
    [(name, Finite) for name, _ in PARAMETERS],
    bases=(schema.Table,),
    module=__name__,
)


class PhysicalDocument(schema.Table):
    """A fitted physical model: its design, parameters and warm-start polynomial."""

    model: Literal["physical"]
    design: DesignDocument
    parameters: Parameters
    warm_start: ModelDocument
    format: Format = MODEL_FORMAT
    n_samples: Samples = 0


def check_model_document(data, where=""):
    """Validate a parsed coefficient document against its schema.

    Parameters
    ----------
    data : object
        The parsed JSON.
    where : str, optional
        The key path of the document in a larger one, for messages.

    Returns
    -------
    ModelDocument or PhysicalDocument

    Raises
    ------
    InputError
        The first key that breaks the schema.
    """
    physical = isinstance(data, dict) and data.get("model") == PhysicalModel.name
    return schema.convert(data, PhysicalDocument if physical else ModelDocument, where=where)


def json_schema():
    """The JSON Schema of a coefficient file (``docs/calibration-model.schema.json``).

    Returns
    -------
    dict
    """
    return schema.json_schema(
        (ModelDocument, PhysicalDocument), f"calibration model ({MODEL_FORMAT})"
    )
