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


def _optics(design, pitch_deg, roll_deg):
    reflector = design.reflector
    hit = trace_axis(
        design.positions_mm,
        design.axes,
        reflector.centre_mm,
        reflector.radius_mm,
        pitch_deg,
        roll_deg,
        detector_direction=[s.detector_direction for s in design.sensors],
    )
    models = design.models
    eta = coupling(
        hit.axial_distance_mm,
        hit.normal_a,
        hit.normal_u,
        hit.normal_w,
        np.array([m.emitter_detector_mm for m in models]),
        source_radius_mm=np.array([m.source_radius_mm for m in models]),
        divergence_deg=np.array([m.divergence_deg for m in models]),
        detector_area_mm2=np.array([m.detector_area_mm2 for m in models]),
        reflectance=reflector.reflectance,
        mirror_radius_mm=reflector.radius_mm,
    )
    if any(m.measured_curve is not None for m in models):
        correction = [
            m.flat_correction(hit.axial_distance_mm[..., i]) for i, m in enumerate(models)
        ]
        eta = eta * np.stack(np.broadcast_arrays(*correction), axis=-1)
    return hit, eta


def _volts(design, eta):
    models = design.models
    if all(m == models[0] for m in models):
        return models[0].output_voltage(eta)
    return np.stack([m.output_voltage(eta[..., i]) for i, m in enumerate(models)], axis=-1)


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
    hit, eta = _optics(design, pitch_deg, roll_deg)
    spot_u, spot_w = spot_displacement(
        hit.axial_distance_mm, hit.normal_a, hit.normal_u, hit.normal_w
    )
    return Response(
        pitch_deg=np.asarray(pitch_deg, dtype=float),
        roll_deg=np.asarray(roll_deg, dtype=float),
        distance_mm=hit.surface_distance_mm,
        axial_distance_mm=hit.axial_distance_mm,
        spot_offset_mm=np.hypot(spot_u, spot_w),
        coupling=eta,
        volts=_volts(design, eta),
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
    _, eta = _optics(design, pitch_deg, roll_deg)
    return _volts(design, eta)
