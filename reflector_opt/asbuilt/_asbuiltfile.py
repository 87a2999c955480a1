"""``AS_BUILT.json`` (``reflector-opt/as-built@1``): what an identification found, per unit.

The document holds the design the units were printed from, the prior, the fit's figures, the
batch's shared surface and, per unit in the order of the unit ids in the data: every
parameter's estimate, design value, standard uncertainty, prior std, posterior/prior ratio
and whether the data determine it (with the 90 % profile-likelihood interval where one was
computed); the covariance of the shared and unit parameters; the combinations the data
determine, in words; the unit's gain and offset; with the angle reference's parameters in
the fit, ``reference``: its zero offsets and twist in that unit's calibration, each with the
parameter it is most correlated with and the determined combination it enters (absent in
files written before they were fitted, and when the reference was taken as exact: read as
an exact reference); ``model_form``: the amplitudes of the model-form signatures of each
sensor (absent in older files and without them); and ``as_built``, a complete design in the
``design.json`` format describing the unit as it was built, which
:meth:`reflector_opt.design.Design.from_dict`, ``evaluate``, ``report`` and ``estimate`` accept.
An optional ``batch`` names the print batch the units came from (``identify --batch``), so
that ``correct`` can refuse files of different batches pooled together.
:class:`AsBuiltDocument` declares the keys; docs/as-built.schema.json is its JSON Schema.
"""

from dataclasses import dataclass
from typing import Annotated

import msgspec
import numpy as np
from msgspec import Meta

from reflector_opt.design._design import Design
from reflector_opt.design._schema import DesignDocument
from reflector_opt.model._noise import Mismatch
from reflector_opt.util import _schema as schema
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import read_json, write_json

AS_BUILT_FORMAT = "reflector-opt/as-built@1"

Finite = Annotated[float, Meta(ge=-1e6, le=1e6)]
Std = Annotated[float, Meta(ge=0, le=1e6)]
BatchName = Annotated[str, Meta(min_length=1, max_length=200, pattern=r"^\S(.*\S)?$")]


class Interval(schema.Table):
    """A profile-likelihood interval of a parameter, in its absolute value."""

    level: Annotated[float, Meta(gt=0, lt=1)]
    low: Finite
    high: Finite
    closed: bool


class Parameter(schema.Table):
    """One parameter: estimate and design value (in the unit its name ends with)."""

    estimate: Finite
    design: Finite
    std: Std
    prior_std: Std
    posterior_prior_ratio: Std
    identifiable: bool
    model_form_std: Std = 0.0
    interval_90: Interval | None = None


class ReferenceParameter(Parameter, kw_only=True):
    """One parameter of the angle reference (degrees), and what the data cannot tell it from:
    the parameter its posterior is most correlated with, the correlation, and the determined
    combination it enters (None: none)."""

    correlated_with: str
    correlation: Annotated[float, Meta(ge=-1.000001, le=1.000001)]
    combination: str | None = None


class Covariance(schema.Table):
    """Covariance of the shared parameters and a unit's, named in order: the whole, and the
    systematic part of it from physics the model lacks (the same in every unit)."""

    names: list[str]
    matrix: list[list[Finite]]
    model_form: list[list[Finite]] | None = None


class Combination(schema.Table):
    """A combination of parameters the data determine (weights in prior-std units)."""

    name: str
    weights: dict[str, Finite]
    posterior_prior_ratio: Std


class ReadOut(schema.Table):
    """Each sensor's identified gain (factor) and offset (V)."""

    gain: list[Finite]
    offset_v: list[Finite]


class Unit(schema.Table):
    """One identified unit."""

    unit: str
    parameters: dict[str, Parameter]
    covariance: Covariance
    as_built: DesignDocument
    read_out: ReadOut
    determined: list[Combination] = msgspec.field(default_factory=list)
    n_samples: Annotated[int, Meta(ge=0)] = 0
    n_curves: Annotated[int, Meta(ge=0)] = 0
    residual_rms_v: list[Std] = msgspec.field(default_factory=list)
    reference: dict[str, ReferenceParameter] | None = None
    model_form: dict[str, Parameter] | None = None


class Fit(schema.Table):
    """Figures of the fit."""

    noise_inflation: Annotated[float, Meta(ge=1)]
    reference_sigma_deg: Std
    seconds: Std
    evaluations: Annotated[int, Meta(ge=0)]


class Prior(schema.Table):
    """The prior: the tolerance model's spreads, the surface's std and the angle reference's
    (degrees; None: the reference taken as exact)."""

    tolerances: dict[str, dict[str, Finite | str] | bool]
    surface_std: dict[str, Std]
    reference_std: dict[str, Std] | None = None
    subsurface_std: Std | None = None
    model_form: dict[str, Finite | str] | None = None


class AsBuiltDocument(schema.Table):
    """An ``AS_BUILT.json`` document."""

    format: Annotated[str, Meta(pattern="^reflector-opt/as-built@1$")]
    design: DesignDocument
    prior: Prior
    fit: Fit
    shared: dict[str, Parameter]
    units: Annotated[list[Unit], Meta(min_length=1)]
    source: str | None = None
    batch: BatchName | None = None


def identification_to_dict(result, source=None, batch=None):
    """The ``AS_BUILT.json`` document of an identification.

    Parameters
    ----------
    result : reflector_opt.asbuilt._result.Identification
    source : str, optional
        The calibration file's name, recorded.
    batch : str, optional
        The print batch the units came from, recorded (1–200 characters, no leading or
        trailing space).

    Returns
    -------
    dict
    """
    layout = result.layout
    units = [_unit_document(result, u, label) for u, label in enumerate(result.labels)]
    document = {  # numpy scalars and arrays as Python numbers and lists, below
        "format": AS_BUILT_FORMAT,
        "source": source,
        "batch": check_batch_name(batch),
        "design": layout.design.to_dict(),
        "prior": {
            "tolerances": layout.tolerances.to_dict(),
            "surface_std": dict(layout.surface_std),
            "reference_std": layout.reference_std,
            "subsurface_std": layout.subsurface_std,
            "model_form": None if result.terms is None else result.terms.model_form.to_dict(),
        },
        "fit": {
            "noise_inflation": float(result.inflation),
            "reference_sigma_deg": result.reference_sigma_deg,
            "seconds": float(result.seconds),
            "evaluations": int(result.evaluations),
        },
        "shared": result.shared_parameters(),
        "units": units,
    }
    return msgspec.to_builtins(document, enc_hook=lambda v: v.tolist())


def _unit_document(result, u, label):
    """The ``units[]`` entry of unit ``u`` of an identification."""
    layout = result.layout
    design, mismatch = result.as_built(u)
    names = [
        *layout.shared_names,
        *layout.unit_names,
        *layout.reference_names,
        *layout.model_form_names,
    ]
    return {
        "unit": label,
        "parameters": result.unit_parameters(u),
        "covariance": {
            "names": names,
            "matrix": result.unit_covariance(u).tolist(),
            "model_form": result.unit_covariance(u, systematic=True).tolist(),
        },
        "determined": [c.to_dict() for c in result.combinations[u]],
        "as_built": design.to_dict(),
        "read_out": {"gain": list(mismatch.gain), "offset_v": list(mismatch.offset_v)},
        "n_samples": int(result.n_samples[u]),
        "n_curves": int(result.n_curves[u]),
        "residual_rms_v": result.residual_rms_v[u].tolist(),
        "reference": result.reference_parameters(u) or None,
        "model_form": result.model_form_parameters(u) or None,
    }


def check_batch_name(batch):
    """A batch name as given, or None; InputError if it is empty, too long or padded.

    Parameters
    ----------
    batch : str or None

    Returns
    -------
    str or None
    """
    if batch is None:
        return None
    if not isinstance(batch, str) or not 1 <= len(batch) <= 200 or batch != batch.strip():
        raise InputError(
            f"batch: expected a name of 1 to 200 characters without leading or trailing "
            f"space, got {batch!r}"
        )
    return batch


def save_as_built(result, path, source=None, batch=None):
    """Write the ``AS_BUILT.json`` of an identification atomically.

    Parameters
    ----------
    result : reflector_opt.asbuilt._result.Identification
    path : str or pathlib.Path
    source : str, optional
        The calibration file's name, recorded.
    batch : str, optional
        The print batch the units came from, recorded.
    """
    write_json(path, identification_to_dict(result, source, batch))


@dataclass(frozen=True)
class AsBuiltFile:
    """A read ``AS_BUILT.json``.

    Attributes
    ----------
    design : reflector_opt.design._design.Design
        The design the units were printed from.
    shared : dict
        The shared parameters' rows.
    units : list of dict
        Per unit: ``unit``, ``parameters``, ``covariance`` (names, numpy matrix),
        ``as_built`` (a Design), ``read_out`` (a Mismatch), ``determined``.
    document : dict
        The document as read.
    batch : str or None
        The print batch recorded by ``identify --batch``, if any.
    """

    design: Design
    shared: dict
    units: list
    document: dict
    batch: str | None = None


def is_as_built_file(path):
    """Whether a JSON file declares the as-built format (False if unreadable: its own
    reader then names the problem).

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    bool
    """
    try:
        data = read_json(path)
    except InputError:
        return False
    return isinstance(data, dict) and data.get("format") == AS_BUILT_FORMAT


def load_as_built(path):
    """Read and check an ``AS_BUILT.json``.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    AsBuiltFile

    Raises
    ------
    InputError
        Unreadable, not this format, a key that breaks the schema, or a design that is not
        valid (each message names the file).
    """
    data = read_json(path)
    if isinstance(data, dict) and data.get("format", AS_BUILT_FORMAT) != AS_BUILT_FORMAT:
        raise InputError(
            f"{path}: format {data.get('format')!r} is not an as-built file ({AS_BUILT_FORMAT})"
        )
    document = schema.convert(data, AsBuiltDocument, where=str(path))
    raw = msgspec.to_builtins(document)
    try:
        design = Design.from_dict(raw["design"])
        units = []
        for k, unit in enumerate(raw["units"]):
            size = len(unit["covariance"]["names"])
            for key in ("matrix", "model_form"):
                given = unit["covariance"].get(key)
                if given is not None and np.shape(given) != (size, size):
                    raise InputError(
                        f"units[{k}].covariance.{key}: a {size} × {size} matrix expected, "
                        f"got shape {np.shape(given)}"
                    )
            matrix = np.array(unit["covariance"]["matrix"], dtype=float)
            units.append(
                {
                    **unit,
                    "covariance": {**unit["covariance"], "matrix": matrix},
                    "as_built": Design.from_dict(unit["as_built"]),
                    "read_out": Mismatch(
                        tuple(unit["read_out"]["gain"]), tuple(unit["read_out"]["offset_v"])
                    ),
                }
            )
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
    return AsBuiltFile(design, raw["shared"], units, raw, raw.get("batch"))


def json_schema():
    """The JSON Schema of ``AS_BUILT.json`` (``docs/as-built.schema.json``).

    Returns
    -------
    dict
    """
    return schema.json_schema(AsBuiltDocument, f"AS_BUILT.json ({AS_BUILT_FORMAT})")
