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

from __future__ import annotations

import numpy as np

from reflector_opt.errors import CollisionError

__all__ = [
    "AxisHit",
    "rotate_centre",
    "rotation_x",
    "rotation_y",
    "sensor_distance",
    "surface_normal",
    "trace_axis",
    "unit",
]


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
    a = np.deg2rad(np.asarray(roll_deg, dtype=float))
    c, s = np.cos(a), np.sin(a)
    one, zero = np.ones_like(a), np.zeros_like(a)
    return np.stack(
        [np.stack([one, zero, zero], -1), np.stack([zero, c, -s], -1), np.stack([zero, s, c], -1)],
        -2,
    )


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
    g = np.deg2rad(np.asarray(pitch_deg, dtype=float))
    c, s = np.cos(g), np.sin(g)
    one, zero = np.ones_like(g), np.zeros_like(g)
    return np.stack(
        [np.stack([c, zero, s], -1), np.stack([zero, one, zero], -1), np.stack([-s, zero, c], -1)],
        -2,
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
    """
    x, y, z = np.asarray(centre_mm, dtype=float)
    g = np.deg2rad(np.asarray(pitch_deg, dtype=float))
    a = np.deg2rad(np.asarray(roll_deg, dtype=float))
    cg, sg, ca, sa = np.cos(g), np.sin(g), np.cos(a), np.sin(a)
    x1 = x * cg + z * sg
    z1 = z * cg - x * sg
    return np.stack(np.broadcast_arrays(x1, y * ca - z1 * sa, y * sa + z1 * ca), axis=-1)


def _pose_first(s1, sensor):
    """Broadcast rotated centres ``P + (3,)`` against sensor vectors ``S + (3,)``."""
    sensor = np.asarray(sensor, dtype=float)
    n_sensor_axes = sensor.ndim - 1
    s1 = s1.reshape(s1.shape[:-1] + (1,) * n_sensor_axes + (3,))
    return s1, sensor


def _check_collision(distance, what="sensor"):
    inside = distance <= 0.0
    if np.any(inside):
        n = int(np.count_nonzero(inside))
        raise CollisionError(
            f"{what} lies on or inside the reflector sphere at {n} pose(s) "
            f"(deepest {-float(np.min(distance)):.4g} mm inside)"
        )


def sensor_distance(sensor_mm, centre_mm, radius_mm, pitch_deg, roll_deg, on_collision="raise"):
    """Shortest sensor-to-reflector distance, d = |f − s1| − r_s (paper Eqs 1–3).

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
        (default) raises :class:`~reflector_opt.errors.CollisionError`; ``"nan"`` marks those
        entries NaN. A collision is never returned as a negative distance.

    Returns
    -------
    numpy.ndarray
        Shape ``P + S``, distance d in mm, with d > 0.

    References
    ----------
    Osman et al. (2024), Eqs 1–3.
    """
    s1, f = _pose_first(rotate_centre(centre_mm, pitch_deg, roll_deg), sensor_mm)
    p = f - s1
    d = np.sqrt(np.einsum("...i,...i->...", p, p)) - float(radius_mm)
    if on_collision == "raise":
        _check_collision(d)
    elif on_collision == "nan":
        d = np.where(d > 0.0, d, np.nan)
    else:
        raise ValueError(f"on_collision must be 'raise' or 'nan', not {on_collision!r}")
    return d


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
        Shape ``P + S + (3,)``: (f − s1)/|f − s1|, the direction from the rotated centre to the
        sensor, which is the outward normal at the nearest surface point.
    """
    s1, f = _pose_first(rotate_centre(centre_mm, pitch_deg, roll_deg), sensor_mm)
    return unit(f - s1)


class AxisHit:
    """Where each sensor's optical axis meets the reflector sphere, at every pose.

    Attributes
    ----------
    surface_distance_mm : numpy.ndarray, shape P + S
        Shortest sensor-to-surface distance d = |f − s1| − r_s (paper Eq 3), mm.
    axial_distance_mm : numpy.ndarray, shape P + S
        Distance t along the optical axis to the first intersection, mm; NaN where the axis
        misses the sphere.
    point_mm : numpy.ndarray, shape P + S + (3,)
        The intersection point q = f + t·a, mm.
    normal : numpy.ndarray, shape P + S + (3,)
        Outward unit normal n at q.
    """

    __slots__ = ("axial_distance_mm", "normal", "point_mm", "surface_distance_mm")

    def __init__(self, surface_distance_mm, axial_distance_mm, point_mm, normal):
        self.surface_distance_mm = surface_distance_mm
        self.axial_distance_mm = axial_distance_mm
        self.point_mm = point_mm
        self.normal = normal

    @property
    def hit(self):
        """Boolean mask, shape P + S: True where the axis meets the sphere."""
        return np.isfinite(self.axial_distance_mm)

    def incidence_deg(self, axis):
        """Angle between the reversed axis −a and the normal n at the hit, degrees.

        Parameters
        ----------
        axis : array_like, shape S + (3,)
            Unit optical axes a.

        Returns
        -------
        numpy.ndarray
            Shape P + S; 0 at normal incidence, NaN where the axis misses.
        """
        cos_inc = -np.einsum("...i,...i->...", self.normal, np.asarray(axis, dtype=float))
        return np.rad2deg(np.arccos(np.clip(cos_inc, -1.0, 1.0)))


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


def trace_axis(sensor_mm, axis, centre_mm, radius_mm, pitch_deg, roll_deg):
    """Eq 3 distance and the ray–sphere intersection of each sensor's optical axis.

    Solves ``|f + t·a − s1| = r_s`` for the smallest t > 0 (a unit), which is the distance
    along the axis, an alternative to the shortest distance of Eq 3 that the optics uses.

    Parameters
    ----------
    sensor_mm : array_like, shape S + (3,)
        Sensor positions f, mm.
    axis : array_like, shape S + (3,)
        Optical axis directions a (normalised here), pointing from the sensor to the reflector.
    centre_mm : array_like, shape (3,)
        Sphere centre s0 at zero pose, mm.
    radius_mm : float
        Sphere radius r_s, mm.
    pitch_deg, roll_deg : array_like
        Pose angles in degrees, broadcast to shape P.

    Returns
    -------
    AxisHit
        Raises :class:`~reflector_opt.errors.CollisionError` if a sensor is on or inside the
        sphere at any pose.

    References
    ----------
    Osman et al. (2024), Eqs 1–3.
    """
    s1, f = _pose_first(rotate_centre(centre_mm, pitch_deg, roll_deg), sensor_mm)
    a = unit(axis)
    p = f - s1
    p_sq = np.einsum("...i,...i->...", p, p)
    r = float(radius_mm)
    surface = np.sqrt(p_sq) - r
    _check_collision(surface)
    b = np.einsum("...i,...i->...", p, a)
    disc = b * b - (p_sq - r * r)
    with np.errstate(invalid="ignore"):
        t = -b - np.sqrt(disc)
    t = np.where((disc >= 0.0) & (t > 0.0), t, np.nan)
    q = f + t[..., None] * a
    return AxisHit(surface, t, q, (q - s1) / r)
