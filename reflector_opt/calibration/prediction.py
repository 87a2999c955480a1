"""Summary of a design over its workspace: sensor windows and predicted calibration errors."""

from __future__ import annotations

import numpy as np

from reflector_opt.analysis.surface import resolution_against_surface
from reflector_opt.calibration.models import make_model
from reflector_opt.calibration.segment import AXES, table_one, workspace_amplitude_deg
from reflector_opt.calibration.simulation import assess, run_protocol
from reflector_opt.design import default_design
from reflector_opt.model.forward import respond
from reflector_opt.util.progress import no_progress

__all__ = ["CALIBRATION_MODELS", "SEGMENT_MODEL", "evaluate_design", "predicted_performance"]

#: Calibration models whose predicted errors :func:`predicted_performance` reports.
CALIBRATION_MODELS = ("eq5", "eq6")
#: The calibration model of the segment figures (the paper's).
SEGMENT_MODEL = "eq6"


def predicted_performance(design, seed=0):
    """Predicted calibration and segment errors of a design (simulated, seeded).

    Runs the paper's calibration protocol on the forward model
    (:func:`reflector_opt.calibration.simulation.run_protocol`: the workspace grid at its step, the
    design's noise, 20,000 validation poses), fits each of :data:`CALIBRATION_MODELS` by
    least squares, and sweeps a segment of ``mechanics.n_units`` units through the paper's
    ±60° pitch and roll motions (smaller if the workspace requires) with the Eq 6
    calibration.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    seed : int

    Returns
    -------
    dict
        JSON-ready: ``calibration.<model>.{rms_deg, max_deg, percent_error, misfit_rms_deg,
        noise_rms_deg}.{pitch, roll}`` (degrees; percent = 100 × RMS / workspace span) and
        ``calibration.protocol``; ``segment.{pitch, roll}.{predicted, paper}`` Table-I-style
        figures (None when the workspace excludes the zero pose, so no motion about it fits).
        Both blocks are None unless the design has exactly two sensors (the calibration
        models map two voltages).
    """
    if len(design.sensors) != 2:
        return {"calibration": None, "segment": None}
    protocol = run_protocol(design, seed=seed)
    calibration = {
        "protocol": {
            "step_deg": protocol.step_deg,
            "n_calibration": len(protocol.calibration.angles_deg),
            "n_validation": len(protocol.validation.angles_deg),
            "noise": design.noise.to_dict(),
            "seed": seed,
        }
    }
    fitted = {}
    for name in CALIBRATION_MODELS:
        result = assess(make_model(name), protocol)
        calibration[name] = result.to_dict()
        fitted[name] = result.model
    segment = None
    if all(workspace_amplitude_deg(design, axis) > 0 for axis in AXES):
        segment = {
            "n_units": design.mechanics.n_units,
            "link_length_mm": design.mechanics.link_length_mm,
            "model": SEGMENT_MODEL,
            **table_one(design, fitted[SEGMENT_MODEL], seed=seed),
        }
    return {"calibration": calibration, "segment": segment}


def evaluate_design(design, predict=True, seed=0, progress=None):
    """Distance and voltage range of every sensor over the design's workspace grid.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    predict : bool
        Add the predicted calibration and segment errors (:func:`predicted_performance`).
    seed : int
        Seed of the simulated calibration.
    progress : callable, optional
        ``progress(fraction, message)`` before each step
        (:class:`~reflector_opt.util.progress.Progress`).

    Returns
    -------
    dict
        JSON-ready: ``sensors[i].distance_mm.{min,max}`` (mm), ``volts.{min,max}`` (V),
        ``margin_mm`` (distance to the nearer end of the usable range, negative outside),
        ``in_range`` per sensor and overall; ``surface``: the reflector's reflectance and
        specular fraction and the worst-case 1σ resolution (degrees) of this design and of
        the built-in default design against the specular fraction
        (:func:`~reflector_opt.analysis.surface.resolution_against_surface`); with
        ``predict``, ``calibration`` and ``segment`` blocks.
    """
    progress = progress or no_progress
    progress(0.0, "distance and voltage windows")
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
    progress(0.1, "resolution against the specular fraction")
    summary = {
        "workspace": {**design.workspace.to_dict(), "poses": int(np.broadcast(pitch, roll).size)},
        "sensors": sensors,
        "in_range": all(s["in_range"] for s in sensors),
        "surface": {
            "reflectance": design.reflector.reflectance,
            "specular_fraction": design.reflector.specular_fraction,
            "resolution_against_specular_fraction": {
                "design": resolution_against_surface(design),
                "default_design": resolution_against_surface(default_design()),
            },
        },
    }
    if predict:
        progress(0.3, "simulated calibration and segment errors")
        summary.update(predicted_performance(design, seed=seed))
    progress(1.0, "evaluated")
    return summary
