"""The ``design.json`` document: its format tag, writing a design, reading the parts back.

Keys ``reflector.radius_mm``, ``reflector.centre_mm``, ``sensors[].position_mm``,
``workspace.pitch_deg`` and ``workspace.roll_deg`` are a public contract (format
``reflector-opt/design@1``). :meth:`~reflector_opt.design._design.Design.to_dict`,
:meth:`~reflector_opt.design._design.Design.from_dict` and
:func:`~reflector_opt.design._design.load_design` are built on the two functions here.
"""

import logging
import math

from reflector_opt.design._components import Mechanics, Noise, Reflector, SensorPlacement, Workspace
from reflector_opt.design._schema import FORMAT, check_document
from reflector_opt.design._validation import check_finite_tree
from reflector_opt.model._sensors import SensorModel
from reflector_opt.model._surface import DEFAULT_MATERIAL, MATERIALS
from reflector_opt.util._errors import InputError

logger = logging.getLogger(__name__)


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
        "predicted": design.predicted.to_dict(),
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
        Keyword arguments of :class:`~reflector_opt.design._design.Design` (``reflector``,
        ``sensors``, ``workspace``, ``mechanics``, ``noise``, ``sensor_models``,
        ``predicted``, ``correction``). Raises :class:`~reflector_opt.util._errors.InputError`
        naming the field; the checks on the design as a whole are the ``Design``'s own.
    """
    if not isinstance(data, dict):
        raise InputError("design: expected a JSON object")
    document = check_document(data)  # the declared schema: every key's type and range
    return {
        "reflector": Reflector.from_dict(data["reflector"]),
        "sensors": tuple(
            SensorPlacement.from_dict(s, f"sensors[{i}]") for i, s in enumerate(data["sensors"])
        ),
        "workspace": Workspace.from_dict(data["workspace"]),
        "mechanics": Mechanics.from_dict(data.get("mechanics", {})),
        "noise": Noise.from_dict(data.get("noise", {})),
        "sensor_models": {
            k: SensorModel.from_dict(v, f"sensor_models.{k}")
            for k, v in data.get("sensor_models", {}).items()
        },
        "predicted": check_finite_tree(document.predicted, "predicted"),
        "correction": check_finite_tree(document.correction, "correction"),
    }


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


def first_difference(a, b, *, ignored=(), rel_tol=None, where=()):
    """The first key path where two JSON-like trees (``design.json`` dicts) differ.

    Keys are visited in sorted order, list items in order; a list item's path is its list's
    with ``[k]`` appended (``sensors[0].position_mm``).

    Parameters
    ----------
    a, b : object
        The trees: dicts, lists and scalars.
    ignored : collection of tuple of str, optional
        Key paths left out of the comparison, e.g. ``{("predicted",)}``.
    rel_tol : float, optional
        Numbers (not bools) count as equal within this relative tolerance (and 1e-12
        absolute); None compares them exactly.
    where : tuple of str, optional
        The path of ``a`` and ``b`` within larger trees.

    Returns
    -------
    (str, object, object) or None
        The dotted path and both values there, or None when the trees agree.
    """
    options = {"ignored": ignored, "rel_tol": rel_tol}
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b), key=str):
            if (*where, key) not in ignored:
                found = first_difference(a.get(key), b.get(key), where=(*where, key), **options)
                if found is not None:
                    return found
        return None
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            item = (*where[:-1], f"{where[-1]}[{k}]") if where else (f"[{k}]",)
            found = first_difference(x, y, where=item, **options)
            if found is not None:
                return found
        return None
    numbers = all(isinstance(v, int | float) and not isinstance(v, bool) for v in (a, b))
    if rel_tol is not None and numbers and math.isclose(a, b, rel_tol=rel_tol, abs_tol=1e-12):
        return None
    return None if a == b else (".".join(where), a, b)
