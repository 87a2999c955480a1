"""The forward model of a design: pose → distances → optical coupling → output voltages.

Composes :mod:`reflector_opt.model.geometry` (paper Eqs 1–3 and the optical-axis intersection),
:mod:`~reflector_opt.model.optics` (Eq 4 extended) and :mod:`~.sensors` (electronics).
Vectorised over any shape of poses; sensors are on the last axis of every result.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from reflector_opt.model import kernel
from reflector_opt.model.geometry import check_collision, pose_trig, sensor_frames

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
        ‖Δ‖, the reflected spot centre's displacement in the sensor plane, mm.
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


def _sensor_optics(models):
    """Per sensor: detector offset ‖e‖ (mm), ω0 (mm), tan θ and S_area (mm²), shape (S, 4)."""
    return np.array(
        [
            (
                m.emitter_detector_mm,
                m.source_radius_mm,
                math.tan(math.radians(m.divergence_deg)),
                m.detector_area_mm2,
            )
            for m in models
        ],
        dtype=float,
    )


def _two_dimensional(shape):
    """The pose shape as two dimensions: () → (1, 1), (n,) → (1, n), (n, m) kept, else (1, N)."""
    if len(shape) == 2:
        return shape
    return (1, math.prod(shape))


def _as_layout(values, shape, layout):
    """``values`` broadcast to the pose shape and laid out as ``layout``, copying only if needed."""
    spread = np.broadcast_to(values, shape)
    return spread if spread.shape == layout else spread.reshape(layout)


def _run(design, pitch_deg, roll_deg):
    """The forward model at every pose: a dict of arrays of shape ``P + (n_sensors,)``.

    One compiled pass (:func:`reflector_opt.model.kernel.respond_poses`) gives the geometry and the
    coupling of every sensor at every pose; measured sensor curves and the electronics are
    applied to its result.
    """
    pitch = np.asarray(pitch_deg, dtype=float)
    roll = np.asarray(roll_deg, dtype=float)
    shape = np.broadcast_shapes(pitch.shape, roll.shape)
    # cos and sin of each given angle only, spread over the poses as zero-stride views
    layout = _two_dimensional(shape)
    trig = [_as_layout(c, shape, layout) for c in pose_trig(pitch, roll)]
    models = design.models
    frames = sensor_frames(design.axes, [p.detector_direction for p in design.sensors])
    out = np.empty((4, *layout, len(models)))
    reflector = design.reflector
    kernel.respond_poses(
        *trig,
        np.asarray(reflector.centre_mm, dtype=float),
        design.positions_mm,
        frames,
        float(reflector.radius_mm),
        _sensor_optics(models),
        float(reflector.reflectance),
        out,
    )
    distance, axial, spot, eta = out.reshape((4, *shape, len(models)))
    check_collision(distance)
    volts = np.empty_like(eta)
    for k, model in enumerate(models):
        if model.measured_curve is not None:
            hit = np.isfinite(axial[..., k])
            eta[..., k][hit] *= model.flat_correction(axial[..., k][hit])
        volts[..., k] = model.output_voltage(eta[..., k])
    return {"distance": distance, "axial": axial, "spot": spot, "coupling": eta, "volts": volts}


def respond(design, pitch_deg, roll_deg):
    """Run the full forward model of ``design`` at the given poses.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    pitch_deg, roll_deg : array_like
        Pitch γ and roll α, degrees; broadcast together to shape P.

    Returns
    -------
    Response
        Raises :class:`~reflector_opt.util.errors.CollisionError` if a sensor would lie inside the
        reflector sphere at any pose.
    """
    columns = _run(design, pitch_deg, roll_deg)
    return Response(
        pitch_deg=np.asarray(pitch_deg, dtype=float),
        roll_deg=np.asarray(roll_deg, dtype=float),
        distance_mm=columns["distance"],
        axial_distance_mm=columns["axial"],
        spot_offset_mm=columns["spot"],
        coupling=columns["coupling"],
        volts=columns["volts"],
    )


def voltages(design, pitch_deg, roll_deg):
    """Noise-free output voltages of every sensor, V, shape ``P + (n_sensors,)``.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    pitch_deg, roll_deg : array_like
        Pitch γ and roll α, degrees; broadcast together to shape P.

    Returns
    -------
    numpy.ndarray
    """
    return _run(design, pitch_deg, roll_deg)["volts"]
