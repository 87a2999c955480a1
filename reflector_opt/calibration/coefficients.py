"""Coefficient files: one fitted calibration model as JSON, and back.

The document (``"format": "reflector-opt/calibration-model@1"``) holds the model's name and
constructor parameters, its ``terms``, the raw-voltage ``coefficients`` per angle (the numbers
to program into firmware), the input normalisation used by the fit and the training errors.
Reading keeps the coefficients exactly as written: ``load_model(path).coef_`` equals the
saved ``coef_`` bit for bit (predictions agree to round-off, since they are evaluated in the
normalised inputs).

The lab's multi-unit file (``reflector-opt/calibration@1``) embeds one such document per unit
(:mod:`~reflector_opt.calibration.lab`); the CSV data formats are in
:mod:`~reflector_opt.calibration.files`.
"""

from __future__ import annotations

import numpy as np

from reflector_opt.calibration.models import ANGLES, make_model
from reflector_opt.calibration.physical import PARAMETERS, PhysicalModel
from reflector_opt.design import Design
from reflector_opt.util.errors import InputError
from reflector_opt.util.fileio import read_json, write_json
from reflector_opt.util.limits import check_count

__all__ = ["MODEL_FORMAT", "load_model", "model_from_dict", "model_to_dict", "save_model"]

MODEL_FORMAT = "reflector-opt/calibration-model@1"


def model_to_dict(model):
    """JSON-ready dict of a fitted model's parameters and coefficients (raw-voltage form).

    Parameters
    ----------
    model : Eq5, Eq6, Polynomial or PhysicalModel
        Fitted. A physical model is written with its design, its fitted parameters and its
        warm-start polynomial.

    Returns
    -------
    dict
    """
    model._check_fitted()
    if isinstance(model, PhysicalModel):
        return _physical_to_dict(model)
    out = {
        "format": MODEL_FORMAT,
        "model": model.name,
        "params": model.get_params(),
        "inputs": ["v1", "v2"],
        "terms": model.term_names,
        "coefficients": {a: model.coef_[i].tolist() for i, a in enumerate(ANGLES)},
        "input_centre_v": model.centre_v_.tolist(),
        "input_scale_v": model.scale_v_.tolist(),
        "n_samples": model.n_samples_,
        "solver": model.solver_,
        "training": {
            "rms_deg": dict(zip(ANGLES, model.training_rms_deg_.tolist(), strict=True)),
            "max_deg": dict(zip(ANGLES, model.training_max_deg_.tolist(), strict=True)),
        },
    }
    if hasattr(model, "huber_threshold_deg_"):
        out["huber_threshold_deg"] = model.huber_threshold_deg_.tolist()
    return out


def _physical_to_dict(model):
    """A fitted :class:`PhysicalModel`: its design, parameters and warm-start polynomial."""
    return {
        "format": MODEL_FORMAT,
        "model": model.name,
        "design": model.design.to_dict(),
        "parameters": dict(model.params_),
        "warm_start": model_to_dict(model.warm_start_),
        "n_samples": model.n_samples_,
    }


def _physical_from_dict(data, where):
    for key in ("design", "parameters", "warm_start"):
        if key not in data:
            raise InputError(f"{where}.{key}: missing key")
    try:
        design = Design.from_dict(data["design"])
    except InputError as exc:
        raise InputError(f"{where}.design: {exc}") from None
    parameters = data["parameters"]
    names = [name for name, _ in PARAMETERS]
    if not isinstance(parameters, dict) or sorted(parameters) != sorted(names):
        raise InputError(f"{where}.parameters: expected exactly {', '.join(names)}")
    x = _floats([parameters[name] for name in names], len(names), f"{where}.parameters")
    warm_start = model_from_dict(data["warm_start"], f"{where}.warm_start")
    n_samples = check_count(data.get("n_samples", 0), f"{where}.n_samples", 0, 10**12)
    return PhysicalModel(design).set_fitted(x, warm_start, n_samples)


def save_model(model, path):
    """Write :func:`model_to_dict` of a fitted model as JSON, atomically."""
    write_json(path, model_to_dict(model))


def _floats(value, length, where):
    if not isinstance(value, list) or len(value) != length:
        raise InputError(f"{where}: expected a list of {length} numbers")
    if not all(isinstance(v, int | float) and not isinstance(v, bool) for v in value):
        raise InputError(f"{where}: expected numbers")
    array = np.array(value, dtype=float)
    if not np.isfinite(array).all():
        raise InputError(f"{where}: numbers must be finite")
    return array


def model_from_dict(data, where="calibration"):
    """Rebuild a fitted model from :func:`model_to_dict` output; errors name the field.

    Parameters
    ----------
    data : dict
    where : str
        Prefix for error messages.

    Returns
    -------
    Eq5, Eq6 or Polynomial
    """
    if not isinstance(data, dict):
        raise InputError(f"{where}: expected an object")
    if data.get("model") == PhysicalModel.name:
        return _physical_from_dict(data, where)
    for key in ("model", "coefficients", "input_centre_v", "input_scale_v"):
        if key not in data:
            raise InputError(f"{where}.{key}: missing key")
    params = data.get("params") or {}
    if not isinstance(params, dict):
        raise InputError(f"{where}.params: expected an object")
    params = dict(params)
    fit = params.pop("fit", "lsq")
    degree = params.pop("degree", None)
    try:
        model = make_model(data["model"], fit, **params)
    except TypeError as exc:
        raise InputError(f"{where}.params: {exc}") from None
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
    if degree is not None and degree != getattr(model, "degree", None):
        raise InputError(f"{where}.params.degree: {degree!r} does not match {model.name}")
    n_terms = len(model.terms)
    if "terms" in data and data["terms"] != model.term_names:
        raise InputError(f"{where}.terms: expected {model.term_names}")
    coefficients = data["coefficients"]
    if not isinstance(coefficients, dict):
        raise InputError(f"{where}.coefficients: expected an object with {', '.join(ANGLES)}")
    raw = np.stack(
        [_floats(coefficients.get(a), n_terms, f"{where}.coefficients.{a}") for a in ANGLES]
    )
    centre = _floats(data["input_centre_v"], 2, f"{where}.input_centre_v")
    scale = _floats(data["input_scale_v"], 2, f"{where}.input_scale_v")
    if not (scale > 0).all():
        raise InputError(f"{where}.input_scale_v: must be positive")
    if not model.centred and centre.any():
        raise InputError(f"{where}.input_centre_v: must be zero for {model.name}")
    n_samples = check_count(data.get("n_samples", 0), f"{where}.n_samples", 0, 10**12)
    solver = data.get("solver")
    if solver is not None and not isinstance(solver, str):
        raise InputError(f"{where}.solver: expected a solver name or null, got {solver!r}")
    with np.errstate(over="ignore", invalid="ignore"):  # refused below, by name
        model._set_fitted(centre, scale, n_samples, solver, coef=raw)
    if not np.isfinite(model._coef_scaled).all():
        raise InputError(
            f"{where}.coefficients: too large for input_scale_v (their scaled form overflows)"
        )
    training = data.get("training") or {}
    if not isinstance(training, dict):
        raise InputError(f"{where}.training: expected an object")
    for attr, key in (("training_rms_deg_", "rms_deg"), ("training_max_deg_", "max_deg")):
        block = training.get(key)
        if isinstance(block, dict) and all(a in block for a in ANGLES):
            values = [block[a] for a in ANGLES]
            setattr(model, attr, _floats(values, 2, f"{where}.training.{key}"))
    if "huber_threshold_deg" in data:
        model.huber_threshold_deg_ = _floats(
            data["huber_threshold_deg"], 2, f"{where}.huber_threshold_deg"
        )
    return model


def load_model(path):
    """Read a model written by :func:`save_model`.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    Eq5, Eq6 or Polynomial
    """
    data = read_json(path)
    if not isinstance(data, dict) or data.get("format") != MODEL_FORMAT:
        raise InputError(f"{path}: not a calibration model (format {MODEL_FORMAT!r})")
    return model_from_dict(data, str(path))
