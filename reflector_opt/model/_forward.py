"""The forward model of a design: pose → distances → optical coupling → output voltages.

Composes :mod:`reflector_opt.model._geometry` (paper Eqs 1–3 and the optical-axis intersection),
:mod:`~reflector_opt.model._optics` (Eq 4 extended to the reflector's surface) and
:mod:`~.sensors` (electronics).
Vectorised over any shape of poses; sensors are on the last axis of every result.
"""

import math
from dataclasses import dataclass

import numpy as np

from reflector_opt.model import _kernel as kernel
from reflector_opt.model._geometry import check_collision, pose_trig, sensor_frames
from reflector_opt.model._interpolation import PoseBox, fit_coefficients, interpolate
from reflector_opt.model._operating import readings
from reflector_opt.model._optics import surface_couplings
from reflector_opt.util._display import Summarised, fmt, span


@dataclass(frozen=True, repr=False)
class Response(Summarised):
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
    coupling : numpy.ndarray
        Detected over emitted optical power η (dimensionless).
    volts : numpy.ndarray
        Sensor output voltage, V (noise-free).
    """

    pitch_deg: np.ndarray
    roll_deg: np.ndarray
    distance_mm: np.ndarray
    axial_distance_mm: np.ndarray
    coupling: np.ndarray
    volts: np.ndarray

    # -- display (equality is the dataclass's, field by field) --

    #: Sensors given a line of their own in the short display.
    _SHOWN_SENSORS = 4

    def _summary(self):
        """Title and (label, value) rows: pose ranges, and the ranges of every output."""
        n_sensors = self.volts.shape[-1] if self.volts.ndim else 0
        poses = self.volts.shape[:-1]
        rows = [
            ("pitch", span(*_finite_range(self.pitch_deg), unit="°")),
            ("roll", span(*_finite_range(self.roll_deg), unit="°")),
            ("distance d", span(*_finite_range(self.distance_mm), unit="mm")),
        ]
        axial = span(*_finite_range(self.axial_distance_mm), unit="mm")
        misses = np.isnan(self.axial_distance_mm)
        if misses.any():
            axial += (
                f" (the axis misses at {fmt(100 * misses.mean(), 2, '%')} of pose-sensor pairs)"
            )
        rows += [
            ("axial distance", axial),
            ("coupling η", span(*_finite_range(self.coupling))),
            ("output voltage", span(*_finite_range(self.volts), unit="V")),
        ]
        if n_sensors <= self._SHOWN_SENSORS:
            rows += [
                (f"sensor {k + 1} output", span(*_finite_range(self.volts[..., k]), unit="V"))
                for k in range(n_sensors)
            ]
        count = math.prod(poses)
        title = (
            f"Response: {count} pose{'' if count == 1 else 's'} (shape {tuple(poses)}) × "
            f"{n_sensors} sensors"
        )
        return title, rows


def _finite_range(values):
    """(min, max) of the finite values, or (None, None) if there are none."""
    values = np.asarray(values, dtype=float)
    finite = values[np.isfinite(values)]
    return (float(finite.min()), float(finite.max())) if finite.size else (None, None)


def _geometry(design, pitch, roll, shift_mm=None):
    """Eq 3 distance, axial distance and sphere centres in the sensor frames: (5,) + P + (S,).

    ``shift_mm`` moves the reflector by a vector of the lower body's frame after the rotation
    (the joint's play); it is the same as moving every sensor by its opposite.
    """
    shape = np.broadcast_shapes(pitch.shape, roll.shape)
    # cos and sin of each given angle only, spread over the poses as zero-stride views laid
    # out in two dimensions: () → (1, 1), (n,) → (1, n), (n, m) kept, else (1, N)
    layout = shape if len(shape) == 2 else (1, math.prod(shape))
    trig = [np.broadcast_to(c, shape).reshape(layout) for c in pose_trig(pitch, roll)]
    frames = sensor_frames(design.axes, [p.detector_direction for p in design.sensors])
    out = np.empty((5, *layout, len(design.sensors)))
    kernel.pose_geometry(
        *trig,
        np.asarray(design.reflector.centre_mm, dtype=float),
        design.positions_mm if shift_mm is None else design.positions_mm - shift_mm,
        frames,
        float(design.reflector.radius_mm),
        out,
    )
    return out.reshape((5, *shape, len(design.sensors)))


def _coupling(design, centres_mm):
    """η = ρ · [f · η_mirror + (1 − f) · η_Lambert] for sphere centres in the sensor frames."""
    reflector = design.reflector
    parts = surface_couplings(
        centres_mm, reflector.radius_mm, reflector.specular_fraction, design.models
    )
    return parts.total(reflector.reflectance, reflector.specular_fraction)


def _interpolated_coupling(design, pitch, roll, shift_mm=None):
    """The coupling at many poses from its values at the Chebyshev points of their box."""
    box = PoseBox.around(pitch, roll)
    if box is None or box.nodes**2 >= np.broadcast(pitch, roll).size:
        return None
    node_pitch, node_roll = box.points()
    centres = np.moveaxis(_geometry(design, node_pitch, node_roll, shift_mm)[2:], 0, -1)
    return interpolate(box, fit_coefficients(box, _coupling(design, centres)), pitch, roll)


def _run(design, pitch_deg, roll_deg, shift_mm=None):
    """The forward model at every pose: a dict of arrays of shape ``P + (n_sensors,)``.

    One compiled pass (:func:`reflector_opt.model._kernel.pose_geometry`) gives the geometry
    of every sensor at every pose. The coupling is computed by
    :func:`reflector_opt.model._optics.surface_couplings` at every pose, or, for many poses,
    at the Chebyshev points of their box and interpolated (:mod:`.interpolation`). Measured
    sensor curves and the electronics are applied to the result.
    """
    pitch = np.asarray(pitch_deg, dtype=float)
    roll = np.asarray(roll_deg, dtype=float)
    shift = None if shift_mm is None else np.asarray(shift_mm, dtype=float)
    distance, axial, *centre = _geometry(design, pitch, roll, shift)
    check_collision(distance)
    eta = _interpolated_coupling(design, pitch, roll, shift)
    if eta is None:
        eta = _coupling(design, np.stack(centre, axis=-1))
    eta = np.maximum(eta, 0.0)
    for k, model in enumerate(design.models):
        if model.measured_curve is not None:
            hit = np.isfinite(axial[..., k])
            eta[..., k][hit] *= model.flat_correction(axial[..., k][hit])
    volts = readings(eta, design.models)
    return {"distance": distance, "axial": axial, "coupling": eta, "volts": volts}


def respond(design, pitch_deg, roll_deg):
    """Run the full forward model of ``design`` at the given poses.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    pitch_deg, roll_deg : array_like
        Pitch γ and roll α, degrees; broadcast together to shape P.

    Returns
    -------
    Response
        Raises :class:`~reflector_opt.util._errors.CollisionError` if a sensor would lie inside the
        reflector sphere at any pose.
    """
    columns = _run(design, pitch_deg, roll_deg)
    return Response(
        pitch_deg=np.asarray(pitch_deg, dtype=float),
        roll_deg=np.asarray(roll_deg, dtype=float),
        distance_mm=columns["distance"],
        axial_distance_mm=columns["axial"],
        coupling=columns["coupling"],
        volts=columns["volts"],
    )


def voltages(design, pitch_deg, roll_deg, *, reflector_shift_mm=None):
    """Noise-free output voltages of every sensor, V, shape ``P + (n_sensors,)``.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    pitch_deg, roll_deg : array_like
        Pitch γ and roll α, degrees; broadcast together to shape P.
    reflector_shift_mm : array_like, shape (3,), optional
        A translation of the reflector in the lower body's frame after the rotation, mm: the
        joint's play (s1 = Rx(α)·Ry(γ)·s0 + δ in paper Eq 1).

    Returns
    -------
    numpy.ndarray
    """
    return _run(design, pitch_deg, roll_deg, reflector_shift_mm)["volts"]
