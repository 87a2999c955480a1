"""Summary of a design over its workspace: distance and voltage windows per sensor."""

from __future__ import annotations

import numpy as np

from reflector_opt.forward import respond

__all__ = ["evaluate_design"]


def evaluate_design(design):
    """Distance and voltage range of every sensor over the design's workspace grid.

    Parameters
    ----------
    design : reflector_opt.design.Design

    Returns
    -------
    dict
        JSON-ready: ``sensors[i].distance_mm.{min,max}`` (mm), ``volts.{min,max}`` (V),
        ``margin_mm`` (distance to the nearer end of the usable range, negative outside),
        ``in_range`` per sensor and overall.
    """
    pitch, roll = design.workspace.grid()
    response = respond(design, pitch, roll)
    sensors = []
    for i, (placement, model) in enumerate(zip(design.sensors, design.models, strict=True)):
        d = response.distance_mm[..., i]
        v = response.volts[..., i]
        lo, hi = model.range_mm
        margin = min(float(d.min()) - lo, hi - float(d.max()))
        sensors.append(
            {
                "name": placement.name,
                "model": model.name,
                "range_mm": [lo, hi],
                "distance_mm": {"min": float(d.min()), "max": float(d.max())},
                "volts": {"min": float(v.min()), "max": float(v.max())},
                "margin_mm": margin,
                "in_range": margin >= 0.0,
            }
        )
    return {
        "workspace": {**design.workspace.to_dict(), "poses": int(np.broadcast(pitch, roll).size)},
        "sensors": sensors,
        "in_range": all(s["in_range"] for s in sensors),
    }
