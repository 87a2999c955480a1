"""The ``design.json`` document: its format tag, writing a design, reading the parts back.

Keys ``reflector.radius_mm``, ``reflector.centre_mm``, ``sensors[].position_mm``,
``workspace.pitch_deg`` and ``workspace.roll_deg`` are a public contract (format
``reflector-opt/design@1``). :meth:`~reflector_opt.design.design.Design.to_dict`,
:meth:`~reflector_opt.design.design.Design.from_dict` and
:func:`~reflector_opt.design.design.load_design` are built on the two functions here.
"""

from __future__ import annotations

import logging

from reflector_opt.design.components import Mechanics, Noise, Reflector, SensorPlacement, Workspace
from reflector_opt.design.schema import FORMAT, check_document
from reflector_opt.design.validation import check_finite_tree, reject_unknown, require_key
from reflector_opt.model.sensors import SensorModel
from reflector_opt.model.surface import DEFAULT_MATERIAL, MATERIALS
from reflector_opt.util.errors import InputError

__all__ = ["FORMAT", "design_fields_from_dict", "design_to_dict", "warn_of_assumptions"]

logger = logging.getLogger(__name__)

_KEYS = (
    "format",
    "reflector",
    "sensors",
    "workspace",
    "mechanics",
    "noise",
    "sensor_models",
    "predicted",
    "correction",
)


def design_to_dict(design):
    """The ``design.json`` document of a design, as a dict.

    Parameters
    ----------
    design : reflector_opt.design.Design

    Returns
    -------
    dict
        JSON-ready; ``sensor_models`` only when the design defines its own, ``correction``
        only when the design carries a print correction.
    """
    out = {
        "format": FORMAT,
        "reflector": design.reflector.to_dict(),
        "sensors": [s.to_dict() for s in design.sensors],
        "workspace": design.workspace.to_dict(),
        "mechanics": design.mechanics.to_dict(),
        "noise": design.noise.to_dict(),
        "predicted": design.predicted,
    }
    if design.correction:
        out["correction"] = design.correction
    if design.sensor_models:
        out["sensor_models"] = {k: m.to_dict() for k, m in design.sensor_models.items()}
    return out


def design_fields_from_dict(data):
    """The parts of a design read and validated from a ``design.json`` dict.

    Parameters
    ----------
    data : dict
        The parsed document.

    Returns
    -------
    dict
        Keyword arguments of :class:`~reflector_opt.design.design.Design` (``reflector``,
        ``sensors``, ``workspace``, ``mechanics``, ``noise``, ``sensor_models``,
        ``predicted``, ``correction``). Raises :class:`~reflector_opt.util.errors.InputError`
        naming the field; the checks on the design as a whole are the ``Design``'s own.
    """
    if not isinstance(data, dict):
        raise InputError("design: expected a JSON object")
    reject_unknown(data, _KEYS, "design")
    fmt = data.get("format", FORMAT)
    if fmt != FORMAT:
        raise InputError(f"format: expected {FORMAT!r}, got {fmt!r}")
    reflector, _ = require_key(data, "reflector")
    sensors, _ = require_key(data, "sensors")
    if not isinstance(sensors, list):
        raise InputError("sensors: expected a list")
    for i, s in enumerate(sensors):
        if not isinstance(s, dict):
            raise InputError(f"sensors[{i}]: expected an object")
    workspace, _ = require_key(data, "workspace")
    for key, block in (("reflector", reflector), ("workspace", workspace)):
        if not isinstance(block, dict):
            raise InputError(f"{key}: expected an object")
    models = data.get("sensor_models", {})
    if not isinstance(models, dict):
        raise InputError("sensor_models: expected an object")
    fields = {
        "reflector": Reflector.from_dict(reflector),
        "sensors": tuple(
            SensorPlacement.from_dict(s, f"sensors[{i}]") for i, s in enumerate(sensors)
        ),
        "workspace": Workspace.from_dict(workspace),
        "mechanics": Mechanics.from_dict(_object(data, "mechanics")),
        "noise": Noise.from_dict(_object(data, "noise")),
        "sensor_models": {
            k: SensorModel.from_dict(v, f"sensor_models.{k}") for k, v in models.items()
        },
        "predicted": check_finite_tree(_object(data, "predicted"), "predicted"),
        "correction": check_finite_tree(_object(data, "correction"), "correction"),
    }
    check_document(data)  # and what no check above covers: the declared schema as a whole
    return fields


def warn_of_assumptions(data):
    """Warn of what reading an accepted ``design.json`` dict had to assume.

    A ``reflector`` block without ``specular_fraction`` was written when the model took
    every reflector for a mirror; it is read as f = 1, the surface the design was made for.
    Called once the whole design is accepted, so that a design refused for another reason
    shows its error alone (docs/conventions.md, "Errors and exit codes").

    Parameters
    ----------
    data : dict
        The parsed document, already read by :func:`design_fields_from_dict`.
    """
    if "specular_fraction" not in data["reflector"]:
        logger.warning(
            "reflector.specular_fraction is absent: read as 1 (a mirror), the surface this "
            "design was made for; set it to model the printed part (white SLA resin: %s)",
            MATERIALS[DEFAULT_MATERIAL].specular_fraction,
        )


def _object(data, key):
    block = data.get(key, {})
    if not isinstance(block, dict):
        raise InputError(f"{key}: expected an object")
    return block
