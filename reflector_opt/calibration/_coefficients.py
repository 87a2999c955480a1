"""Coefficient files: one fitted calibration model as JSON, and back.

The document (``"format": "reflector-opt/calibration-model@1"``) holds the model's name and
constructor parameters, its ``terms``, the raw-voltage ``coefficients`` per angle (the numbers
to program into firmware), the input normalisation used by the fit and the training errors; a
temperature-compensated calibration adds its ``temperature`` block (the reference temperature,
each sensor's pivot, gain and offset change per kelvin with their standard deviations, the
calibration's temperature range: :mod:`~reflector_opt.calibration._temperature`), which the
form's coefficients apply after.
Reading keeps the coefficients exactly as written: ``load_model(path).coef_`` equals the
saved ``coef_`` bit for bit (predictions agree to round-off, since they are evaluated in the
normalised inputs).

The lab's multi-unit file (``reflector-opt/calibration@1``) embeds one such document per unit
(:mod:`~reflector_opt.calibration._unit_calibration`); the CSV data formats are in
:mod:`~reflector_opt.calibration._files`.
"""

import math

import msgspec
import numpy as np

from reflector_opt.calibration._models import ANGLES, make_model, recorded_params
from reflector_opt.calibration._physical import PARAMETERS, PhysicalModel
from reflector_opt.calibration._schema import MODEL_FORMAT, PhysicalDocument, check_model_document
from reflector_opt.calibration._temperature import TemperatureCompensated, ThermalFit
from reflector_opt.design import Design
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import read_json, write_json


def model_to_dict(model):
    """JSON-ready dict of a fitted model's parameters and coefficients (raw-voltage form).

    Parameters
    ----------
    model : Eq5, Eq6, Polynomial, TemperatureCompensated or PhysicalModel
        Fitted. A physical model is written with its design, its fitted parameters and its
        warm-start polynomial; a compensated one as its form with a ``temperature`` block.

    Returns
    -------
    dict
    """
    model._check_fitted()
    if isinstance(model, PhysicalModel):  # its design, parameters and warm-start polynomial
        return {
            "format": MODEL_FORMAT,
            "model": model.name,
            "design": model.design.to_dict(),
            "parameters": dict(model.params_),
            "warm_start": model_to_dict(model.warm_start_),
            "n_samples": model.n_samples_,
        }
    if isinstance(model, TemperatureCompensated):
        return {**model_to_dict(model.form_), "temperature": temperature_block(model)}
    out = {
        "format": MODEL_FORMAT,
        "model": model.name,
        "params": recorded_params(model),
        "inputs": ["v1", "v2"],
        "terms": model.term_names,
        "coefficients": {a: model.coef_[i].tolist() for i, a in enumerate(ANGLES)},
        "input_centre_v": model.centre_v_.tolist(),
        "input_scale_v": model.scale_v_.tolist(),
        "n_samples": model.n_samples_,
        "solver": model.solver_,
        "training": {  # a file read without them (they are optional) is written without
            key: dict(zip(ANGLES, getattr(model, attr).tolist(), strict=True))
            for attr, key in (("training_rms_deg_", "rms_deg"), ("training_max_deg_", "max_deg"))
            if hasattr(model, attr)
        },
    }
    if hasattr(model, "huber_threshold_deg_"):
        out["huber_threshold_deg"] = model.huber_threshold_deg_.tolist()
    return out


def temperature_block(model):
    """The ``temperature`` block of a fitted :class:`TemperatureCompensated`, JSON-ready."""
    thermal = model.thermal_
    return {
        "reference_temperature_c": model.reference_temperature_c_,
        "supply_v": model.supply_v_.tolist(),
        **{k: np.asarray(v).tolist() for k, v in thermal._asdict().items() if v is not None},
        "temperature_range_c": model.temperature_range_c_.tolist(),
    }


def _compensated(form, block):
    """A fitted :class:`TemperatureCompensated` of a plain form and its ``temperature`` block."""
    thermal = ThermalFit(*(getattr(block, key) for key in ThermalFit._fields))
    model = TemperatureCompensated(form.clone(), supply_v=tuple(block.supply_v))
    return model.set_fitted(
        form, block.reference_temperature_c, block.supply_v, thermal, block.temperature_range_c
    )


def _physical_from_document(document, where):
    try:
        design = Design.from_dict(msgspec.to_builtins(document.design))
    except InputError as exc:
        raise InputError(f"{where}.design: {exc}") from None
    x = np.array([getattr(document.parameters, name) for name, _ in PARAMETERS])
    if document.warm_start.temperature is not None:
        raise InputError(f"{where}.warm_start.temperature: the physical model is not compensated")
    warm_start = _model_from_document(document.warm_start, f"{where}.warm_start")
    return PhysicalModel(design).set_fitted(x, warm_start, document.n_samples)


def save_model(model, path):
    """Write :func:`model_to_dict` of a fitted model as JSON, atomically."""
    write_json(path, model_to_dict(model))


def model_from_dict(data, where="calibration"):
    """Rebuild a fitted model from :func:`model_to_dict` output; errors name the field.

    The document is checked against its schema
    (:func:`~reflector_opt.calibration._schema.check_model_document`), then against the model
    it names.

    Parameters
    ----------
    data : dict
    where : str
        Key path of the document, for error messages.

    Returns
    -------
    Eq5, Eq6, Polynomial, TemperatureCompensated or PhysicalModel
    """
    return _model_from_document(check_model_document(data, where), where)


def _check_params(params, where):
    """Refuse constructor parameters of the wrong kind (the schema leaves ``params`` open)."""
    solver, huber = params.get("solver"), params.get("huber_threshold_deg")
    if solver is not None and not isinstance(solver, str):
        raise InputError(f"{where}.solver: expected a solver name or null, got {solver!r}")
    if huber is not None and not (
        isinstance(huber, int | float) and not isinstance(huber, bool) and 0 < huber < math.inf
    ):
        raise InputError(
            f"{where}.huber_threshold_deg: expected a positive number or null, got {huber!r}"
        )
    if not isinstance(params.get("intercept", False), bool):
        raise InputError(f"{where}.intercept: expected true or false")


def _model_from_document(document, where):
    if isinstance(document, PhysicalDocument):
        return _physical_from_document(document, where)
    params = dict(document.params)
    _check_params(params, f"{where}.params")
    fit = params.pop("fit", "lsq")
    degree = params.pop("degree", None)
    try:
        model = make_model(document.model, fit, **params)
    except TypeError as exc:
        raise InputError(f"{where}.params: {exc}") from None
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
    if degree is not None and degree != getattr(model, "degree", None):
        raise InputError(f"{where}.params.degree: {degree!r} does not match {model.name}")
    if document.terms is not None and document.terms != model.term_names:
        raise InputError(f"{where}.terms: expected {model.term_names}")
    n_terms = len(model.terms)
    for angle in ANGLES:
        given = len(getattr(document.coefficients, angle))
        if given != n_terms:
            raise InputError(
                f"{where}.coefficients.{angle}: expected a list of {n_terms} numbers for "
                f"{model.name}, got {given}"
            )
    raw = np.array([getattr(document.coefficients, a) for a in ANGLES])
    centre = np.array(document.input_centre_v)
    if not model.centred and centre.any():
        raise InputError(f"{where}.input_centre_v: must be zero for {model.name}")
    with np.errstate(over="ignore", invalid="ignore"):  # refused below, by name
        model._set_fitted(
            centre, np.array(document.input_scale_v), document.n_samples, document.solver, coef=raw
        )
    if not np.isfinite(model._coef_scaled).all():
        raise InputError(
            f"{where}.coefficients: too large for input_scale_v (their scaled form overflows)"
        )
    for attr, key in (("training_rms_deg_", "rms_deg"), ("training_max_deg_", "max_deg")):
        block = getattr(document.training, key)
        if block is not None:
            setattr(model, attr, np.array([getattr(block, a) for a in ANGLES]))
    if document.huber_threshold_deg is not None:
        model.huber_threshold_deg_ = np.array(document.huber_threshold_deg)
    return model if document.temperature is None else _compensated(model, document.temperature)


def load_model(path):
    """Read a model written by :func:`save_model`.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    Eq5, Eq6, Polynomial, TemperatureCompensated or PhysicalModel
    """
    data = read_json(path)
    if not isinstance(data, dict) or data.get("format") != MODEL_FORMAT:
        raise InputError(f"{path}: not a calibration model (format {MODEL_FORMAT!r})")
    return model_from_dict(data, str(path))
