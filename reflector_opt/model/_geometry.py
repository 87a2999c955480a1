"""Geometry of one rotational unit: paper Eqs 1–3 and the sensor's optical axis.

Frame (see docs/conventions.md): origin O at the spherical bearing's centre, z along the
backbone towards the next unit, x and y in the disk plane. Pitch γ is the active rotation
about y, roll α the active rotation about x, and the reflector centre moves as
``s1 = Rx(α) · Ry(γ) · s0`` (paper Eq 1). Lengths are in millimetres and angles in degrees
at every public boundary.

Broadcasting: pitch and roll broadcast together to a pose shape ``P``; sensor vectors have
shape ``(..., 3)`` with sensor shape ``S``; results have shape ``P + S`` (sensors along the
last axes), so a grid of poses and a pair of sensors give ``(n_pitch, n_roll, 2)``.
"""

from dataclasses import dataclass

import numpy as np

from reflector_opt.model import _rotation as rotation
from reflector_opt.util._errors import CollisionError


def rotation_x(roll_deg):
    """Active rotation matrix about x by the roll angle α.

    Parameters
    ----------
    roll_deg : array_like
        Roll angle α in degrees, any shape ``P``.

    Returns
    -------
    numpy.ndarray
        Shape ``P + (3, 3)``: ``[[1, 0, 0], [0, cos α, −sin α], [0, sin α, cos α]]``.
    """
    return _plane_rotation(roll_deg, 1, 2)


def rotation_y(pitch_deg):
    """Active rotation matrix about y by the pitch angle γ.

    Parameters
    ----------
    pitch_deg : array_like
        Pitch angle γ in degrees, any shape ``P``.

    Returns
    -------
    numpy.ndarray
        Shape ``P + (3, 3)``: ``[[cos γ, 0, sin γ], [0, 1, 0], [−sin γ, 0, cos γ]]``.
    """
    return _plane_rotation(pitch_deg, 2, 0)


def _plane_rotation(angle_deg, i, j):
    """The rotation turning axis i towards axis j, the third fixed, shape ``P + (3, 3)``:
    cos on (i, i) and (j, j), −sin on (i, j), sin on (j, i), 1 on the third axis (filled in
    place: a stack of nine arrays would cost most of a single pose's time)."""
    a = np.deg2rad(np.asarray(angle_deg, dtype=float))
    c, s = np.cos(a), np.sin(a)
    r = np.zeros((*a.shape, 3, 3))
    r[..., 3 - i - j, 3 - i - j] = 1.0
    r[..., i, i] = r[..., j, j] = c
    r[..., i, j], r[..., j, i] = -s, s
    return r


def pose_trig(pitch_deg, roll_deg):
    """cos γ, sin γ, cos α and sin α of pitch γ and roll α given in degrees (shapes kept)."""
    g = np.deg2rad(np.asarray(pitch_deg, dtype=float))
    a = np.deg2rad(np.asarray(roll_deg, dtype=float))
    return np.cos(g), np.sin(g), np.cos(a), np.sin(a)


def _rotated_components(centre_mm, pitch_deg, roll_deg):
    """Components (x1, y1, z1) of s1 = Rx(α) Ry(γ) s0, each broadcastable to the pose shape."""
    # the kernel's scalar formula, evaluated by numpy over the pose arrays
    return rotation.rotated_centre(
        *np.asarray(centre_mm, dtype=float), *pose_trig(pitch_deg, roll_deg)
    )


def rotate_centre(centre_mm, pitch_deg, roll_deg):
    """Reflector centre after the unit rotates: s1 = Rx(α) Ry(γ) s0 (paper Eq 1).

    Written out component by component, so no rotation matrix is built per pose:
    ``Ry s0 = (x cos γ + z sin γ, y, −x sin γ + z cos γ)`` and then ``Rx`` mixes y and z.

    Parameters
    ----------
    centre_mm : array_like, shape (3,)
        Sphere centre s0 at zero pose, mm.
    pitch_deg, roll_deg : array_like
        Pitch γ and roll α in degrees; they broadcast together to the pose shape ``P``.

    Returns
    -------
    numpy.ndarray
        Shape ``P + (3,)``, the rotated centre s1 in mm.

    References
    ----------
    Osman et al. (2024), Eq 1.
    """
    return np.stack(np.broadcast_arrays(*_rotated_components(centre_mm, pitch_deg, roll_deg)), -1)


def sensor_frames(axis, detector_direction):
    """Orthonormal frame (a, u, w) of each sensor.

    Parameters
    ----------
    axis : array_like, shape S + (3,)
        Optical axes, pointing from the sensor to the reflector (normalised here).
    detector_direction : array_like, shape S + (3,)
        LED-to-detector direction; its component along the axis is removed.

    Returns
    -------
    numpy.ndarray
        Shape ``S + (3, 3)``: rows a (axis), u (towards the detector, in the sensor plane) and
        w = a × u.
    """
    a = unit(axis)
    e = np.asarray(detector_direction, dtype=float)
    u = unit(e - np.sum(e * a, axis=-1, keepdims=True) * a)
    return np.stack([a, u, np.cross(a, u)], axis=-2)


def centre_offsets(sensor_mm, frames, centre_mm, pitch_deg, roll_deg):
    """Vector p = f − s1 (paper Eq 2) in each sensor's own frame.

    Parameters
    ----------
    sensor_mm : array_like, shape S + (3,)
        Sensor positions f, mm.
    frames : array_like, shape S + (3, 3)
        Sensor frames from :func:`sensor_frames` (rows a, u, w).
    centre_mm : array_like, shape (3,)
        Sphere centre s0 at zero pose, mm.
    pitch_deg, roll_deg : array_like
        Pose angles in degrees, broadcast to shape P.

    Returns
    -------
    tuple of numpy.ndarray
        (p·a, p·u, p·w), each of shape ``P + S``, mm.

    References
    ----------
    Osman et al. (2024), Eqs 1–2.
    """
    f = np.asarray(sensor_mm, dtype=float)
    frames = np.asarray(frames, dtype=float)
    sensor_axes = tuple(range(-(f.ndim - 1), 0))
    s1 = _rotated_components(centre_mm, pitch_deg, roll_deg)
    s1_x, s1_y, s1_z = (np.expand_dims(c, sensor_axes) for c in s1)
    # p·b = f·b − s1·b for each row b of the frame
    return tuple(
        np.sum(f * b, axis=-1) - (s1_x * b[..., 0] + s1_y * b[..., 1] + s1_z * b[..., 2])
        for b in np.moveaxis(frames, -2, 0)
    )


def _pose_first(s1, sensor):
    """Broadcast rotated centres ``P + (3,)`` against sensor vectors ``S + (3,)``."""
    sensor = np.asarray(sensor, dtype=float)
    return s1.reshape(s1.shape[:-1] + (1,) * (sensor.ndim - 1) + (3,)), sensor


def check_collision(distance_mm):
    """Raise if any Eq 3 distance shows a sensor on or inside the reflector sphere.

    Parameters
    ----------
    distance_mm : numpy.ndarray
        Shortest sensor-to-surface distances d = ‖f − s1‖ − r_s, mm.

    Raises
    ------
    reflector_opt.util._errors.CollisionError
        If any distance is ≤ 0 or NaN, with the number of such entries and the deepest one.
    """
    distance = np.asarray(distance_mm)
    inside = ~(distance > 0.0)
    if np.any(inside):
        raise CollisionError(
            f"a sensor lies on or inside the reflector sphere at {np.count_nonzero(inside)} "
            f"pose(s) (deepest {-float(np.nanmin(distance)):.4g} mm inside)"
        )


def sensor_distance(sensor_mm, centre_mm, radius_mm, pitch_deg, roll_deg, on_collision="raise"):
    """Shortest sensor-to-reflector distance, d = ‖f − s1‖ − r_s (paper Eqs 1–3).

    Parameters
    ----------
    sensor_mm : array_like, shape S + (3,)
        Sensor positions f, mm.
    centre_mm : array_like, shape (3,)
        Reflector sphere centre s0 at zero pose, mm.
    radius_mm : float
        Reflecting sphere radius r_s, mm (> 0).
    pitch_deg, roll_deg : array_like
        Pitch γ (about y) and roll α (about x) in degrees, broadcast together to shape P.
    on_collision : {"raise", "nan"}
        A pose with ``|p| <= r_s`` puts the sensor on or inside the sphere. ``"raise"``
        (default) raises :class:`~reflector_opt.util._errors.CollisionError`; ``"nan"`` marks those
        entries NaN. A collision is never returned as a negative distance.

    Returns
    -------
    numpy.ndarray
        Shape ``P + S``, distance d in mm, with d > 0.

    References
    ----------
    Osman et al. (2024), Eqs 1–3.
    """
    if on_collision not in ("raise", "nan"):
        raise ValueError(f"on_collision must be 'raise' or 'nan', not {on_collision!r}")
    s1, f = _pose_first(rotate_centre(centre_mm, pitch_deg, roll_deg), sensor_mm)
    d = np.linalg.norm(f - s1, axis=-1) - float(radius_mm)
    if on_collision == "raise":
        check_collision(d)
    return np.where(d > 0.0, d, np.nan)


def surface_normal(sensor_mm, centre_mm, pitch_deg, roll_deg):
    """Outward unit normal of the sphere at the point nearest to each sensor.

    Parameters
    ----------
    sensor_mm : array_like, shape S + (3,)
        Sensor positions f, mm.
    centre_mm : array_like, shape (3,)
        Sphere centre s0 at zero pose, mm.
    pitch_deg, roll_deg : array_like
        Pose angles in degrees, broadcast to shape P.

    Returns
    -------
    numpy.ndarray
        Shape ``P + S + (3,)``: (f − s1)/‖f − s1‖, the direction from the rotated centre to the
        sensor, which is the outward normal at the nearest surface point.
    """
    s1, f = _pose_first(rotate_centre(centre_mm, pitch_deg, roll_deg), sensor_mm)
    return unit(f - s1)


def unit(vectors):
    """Normalise vectors along the last axis.

    Parameters
    ----------
    vectors : array_like, shape (..., 3)

    Returns
    -------
    numpy.ndarray
        Same shape, each vector of length 1.
    """
    v = np.asarray(vectors, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def tilted_axis(axis, tilt_deg):
    """An axis tilted by two small angles about two directions across it.

    ``a + |a| (tan t1 · u + tan t2 · w)``, with u = a × e (e the unit-frame axis least aligned
    with a, normalised) and w = â × u: the tilt of a sensor's optical axis in the tolerance
    model and in the physical calibration.

    Parameters
    ----------
    axis : array_like, shape (3,)
        The axis (any length).
    tilt_deg : array_like, shape (2,)
        Tilts t1, t2 about the two directions, degrees.

    Returns
    -------
    tuple of float
        The tilted axis (not normalised; its component along ``axis`` keeps its length).
    """
    a = np.asarray(axis, dtype=float)
    length = np.linalg.norm(a)
    u = np.cross(a, _any_perpendicular(a))
    u /= np.linalg.norm(u)
    w = np.cross(a / length, u)
    t = np.tan(np.deg2rad(np.asarray(tilt_deg, dtype=float)))
    return tuple((a + length * (t[0] * u + t[1] * w)).tolist())


def _any_perpendicular(axis):
    """A direction perpendicular to each axis: the unit-frame axis least aligned with it."""
    a = np.asarray(axis, dtype=float)
    return np.eye(3)[np.argmin(np.abs(a), axis=-1)]


def unit_perpendicular(vectors):
    """A unit vector perpendicular to each unit vector (along the last axis): the unit-frame
    axis least aligned with it, less its component along it."""
    helper = _any_perpendicular(vectors)
    return unit(helper - np.sum(helper * vectors, axis=-1, keepdims=True) * vectors)


@dataclass(frozen=True)
class AxisHit:
    """Where each sensor's optical axis meets the reflector sphere, at every pose.

    Arrays have shape ``P + S``; the normal's components are given in each sensor's frame
    (a, u, w) of :func:`sensor_frames`.

    Attributes
    ----------
    surface_distance_mm : numpy.ndarray
        Shortest sensor-to-surface distance d = ‖f − s1‖ − r_s (paper Eq 3), mm.
    axial_distance_mm : numpy.ndarray
        Distance t along the optical axis to the first intersection, mm; NaN where the axis
        misses the sphere.
    normal_a, normal_u, normal_w : numpy.ndarray
        Components of the outward unit normal n at the hit along a, u and w.
    sensor_mm : numpy.ndarray, shape S + (3,)
        The sensor positions traced, mm.
    frames : numpy.ndarray, shape S + (3, 3)
        The sensor frames used (rows a, u, w).
    """

    surface_distance_mm: np.ndarray
    axial_distance_mm: np.ndarray
    normal_a: np.ndarray
    normal_u: np.ndarray
    normal_w: np.ndarray
    sensor_mm: np.ndarray
    frames: np.ndarray

    @property
    def hit(self):
        """Boolean mask: True where the axis meets the sphere."""
        return np.isfinite(self.axial_distance_mm)

    @property
    def incidence_deg(self):
        """Angle between the reversed axis −a and the normal, degrees (0: normal incidence)."""
        return np.rad2deg(np.arccos(np.clip(-self.normal_a, -1.0, 1.0)))

    @property
    def normal(self):
        """Outward unit normal at the hit in the unit frame, shape ``P + S + (3,)``."""
        local = np.stack([self.normal_a, self.normal_u, self.normal_w], axis=-1)
        return np.einsum("...k,...kj->...j", local, self.frames)

    @property
    def point_mm(self):
        """Hit point q = f + t·a in the unit frame, shape ``P + S + (3,)``, mm."""
        return self.sensor_mm + self.axial_distance_mm[..., None] * self.frames[..., 0, :]


def trace_axis(sensor_mm, axis, centre_mm, radius_mm, pitch_deg, roll_deg, detector_direction=None):
    """Eq 3 distance and the ray–sphere intersection of each sensor's optical axis.

    In the sensor frame, with p = f − s1 = (p_a, p_u, p_w), the axis f + t·a meets the sphere
    ‖x − s1‖ = r_s first at ``t = −p_a − sqrt(r_s² − p_u² − p_w²)``, where the outward normal
    is ``n = (−sqrt(r_s² − p_u² − p_w²), p_u, p_w) / r_s``. t is the distance along the
    axis, an alternative to the shortest distance of Eq 3; the optics uses it.

    Parameters
    ----------
    sensor_mm : array_like, shape S + (3,)
        Sensor positions f, mm.
    axis : array_like, shape S + (3,)
        Optical axes a, pointing from the sensor to the reflector (normalised here).
    centre_mm : array_like, shape (3,)
        Sphere centre s0 at zero pose, mm.
    radius_mm : float
        Sphere radius r_s, mm.
    pitch_deg, roll_deg : array_like
        Pose angles in degrees, broadcast to shape P.
    detector_direction : array_like, shape S + (3,), optional
        Fixes the in-plane direction u of each sensor frame (the LED-to-detector direction);
        any perpendicular direction if omitted.

    Returns
    -------
    AxisHit
        Raises :class:`~reflector_opt.util._errors.CollisionError` if a sensor is on or inside the
        sphere at any pose.

    References
    ----------
    Osman et al. (2024), Eqs 1–3.
    """
    f = np.asarray(sensor_mm, dtype=float)
    if detector_direction is None:
        detector_direction = _any_perpendicular(axis)
    frames = sensor_frames(axis, detector_direction)
    offsets = np.broadcast_arrays(*centre_offsets(f, frames, centre_mm, pitch_deg, roll_deg))
    from reflector_opt.model import _kernel as kernel

    hits = np.empty((5, offsets[0].size))
    kernel.axis_hits(*(np.ravel(p) for p in offsets), float(radius_mm), hits)
    surface, axial, normal_a, normal_u, normal_w = hits.reshape((5, *offsets[0].shape))
    check_collision(surface)
    return AxisHit(
        surface_distance_mm=surface,
        axial_distance_mm=axial,
        normal_a=normal_a,
        normal_u=normal_u,
        normal_w=normal_w,
        sensor_mm=f,
        frames=frames,
    )
