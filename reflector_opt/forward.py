"""The forward model of a design: pose → distances → optical coupling → output voltages.

Composes :mod:`reflector_opt.geometry` (paper Eqs 1–3 and the optical-axis intersection),
:mod:`reflector_opt.optics` (Eq 4 extended) and :mod:`reflector_opt.sensors` (electronics).
Vectorised over any shape of poses; sensors are on the last axis of every result.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reflector_opt.geometry import trace_axis
from reflector_opt.optics import coupling, spot_displacement

__all__ = ["Response", "respond", "voltages"]


@dataclass(frozen=True)
class Response:
    """Everything the forward model computes for a set of poses.

    All arrays have shape ``P + (n_sensors,)``, P the broadcast shape of pitch and roll.

    Attributes
    ----------
    pitch_deg, roll_deg : numpy.ndarray
        The poses, degrees (as given).
    distance_mm : numpy.ndarray
        Shortest sensor-to-reflector distance d (paper Eq 3), mm.
    axial_distance_mm : numpy.ndarray
        Distance along each sensor's optical axis to the reflector, mm (NaN: axis misses).
    spot_offset_mm : numpy.ndarray
        |Δ|, the reflected spot centre's displacement in the sensor plane, mm.
    coupling : numpy.ndarray
        Detected over emitted optical power η (dimensionless).
    volts : numpy.ndarray
        Sensor output voltage, V (noise-free).
    """

    pitch_deg: np.ndarray
    roll_deg: np.ndarray
    distance_mm: np.ndarray
    axial_distance_mm: np.ndarray
    spot_offset_mm: np.ndarray
    coupling: np.ndarray
    volts: np.ndarray


def _one_sensor(design, placement, model, pitch_deg, roll_deg):
    """Axis hit and coupling of one sensor, arrays of the pose shape.

    Sensors are taken one at a time so that every array operation runs over the poses with
    scalar parameters: numpy's inner loops then span whole rows of poses.
    """
    reflector = design.reflector
    hit = trace_axis(
        placement.position_mm,
        placement.axis,
        reflector.centre_mm,
        reflector.radius_mm,
        pitch_deg,
        roll_deg,
        detector_direction=placement.detector_direction,
    )
    eta = coupling(
        hit.axial_distance_mm,
        hit.normal_a,
        hit.normal_u,
        hit.normal_w,
        model.emitter_detector_mm,
        source_radius_mm=model.source_radius_mm,
        divergence_deg=model.divergence_deg,
        detector_area_mm2=model.detector_area_mm2,
        reflectance=reflector.reflectance,
        mirror_radius_mm=reflector.radius_mm,
    )
    if model.measured_curve is not None:
        eta = eta * model.flat_correction(hit.axial_distance_mm)
    return hit, eta


def _sensors(design, pitch_deg, roll_deg):
    for placement, model in zip(design.sensors, design.models, strict=True):
        yield model, *_one_sensor(design, placement, model, pitch_deg, roll_deg)


def respond(design, pitch_deg, roll_deg):
    """Run the full forward model of ``design`` at the given poses.

    Parameters
    ----------
    design : reflector_opt.design.Design
    pitch_deg, roll_deg : array_like
        Pitch γ and roll α, degrees; broadcast together to shape P.

    Returns
    -------
    Response
        Raises :class:`~reflector_opt.errors.CollisionError` if a sensor would lie inside the
        reflector sphere at any pose.
    """
    columns = {k: [] for k in ("distance", "axial", "spot", "coupling", "volts")}
    for model, hit, eta in _sensors(design, pitch_deg, roll_deg):
        spot_u, spot_w = spot_displacement(
            hit.axial_distance_mm, hit.normal_a, hit.normal_u, hit.normal_w
        )
        columns["distance"].append(hit.surface_distance_mm)
        columns["axial"].append(hit.axial_distance_mm)
        columns["spot"].append(np.hypot(spot_u, spot_w))
        columns["coupling"].append(eta)
        columns["volts"].append(model.output_voltage(eta))
    stacked = {k: np.stack(v, axis=-1) for k, v in columns.items()}
    return Response(
        pitch_deg=np.asarray(pitch_deg, dtype=float),
        roll_deg=np.asarray(roll_deg, dtype=float),
        distance_mm=stacked["distance"],
        axial_distance_mm=stacked["axial"],
        spot_offset_mm=stacked["spot"],
        coupling=stacked["coupling"],
        volts=stacked["volts"],
    )


def voltages(design, pitch_deg, roll_deg):
    """Noise-free output voltages of every sensor, V, shape ``P + (n_sensors,)``.

    Parameters
    ----------
    design : reflector_opt.design.Design
    pitch_deg, roll_deg : array_like
        Pitch γ and roll α, degrees; broadcast together to shape P.

    Returns
    -------
    numpy.ndarray
    """
    return np.stack(
        [model.output_voltage(eta) for model, _, eta in _sensors(design, pitch_deg, roll_deg)],
        axis=-1,
    )
