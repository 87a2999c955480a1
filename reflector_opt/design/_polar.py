"""Regions and directions about the rotation centre O: the polar box and its angle helpers.

Angles about O as in :mod:`reflector_opt.design._layout`: elevation e from the xy-plane
(positive towards +z) and azimuth a from +x towards +y, in degrees; lengths in mm. A
:class:`PolarBox` is the shape in which the layout describes the space the rotating parts
sweep (the body keeps out of it); the functions convert between directions and angles,
compare azimuths across ±180° and measure from O to a sphere around it.
"""

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PolarBox:
    """A region about O: r0 ≤ ‖x‖ ≤ r1, e0 ≤ elevation ≤ e1, a0 ≤ azimuth ≤ a1.

    ``a0 = a1 = None`` means every azimuth. Lengths mm, angles degrees.
    """

    r0: float
    r1: float
    e0: float
    e1: float
    a0: float | None = None
    a1: float | None = None

    def lowest_z(self):
        """Lowest z of the box's points, mm."""
        sine = math.sin(math.radians(self.e0))
        return min(self.r0 * sine, self.r1 * sine)

    def horizontal_extent(self):
        """Smallest and largest distance from the z axis of the box's points, mm."""
        lo, hi = sorted((abs(self.e0), abs(self.e1)))
        nearest_to_plane = 0.0 if self.e0 <= 0.0 <= self.e1 else lo
        return (
            self.r0 * math.cos(math.radians(min(hi, 90.0))),
            self.r1 * math.cos(math.radians(nearest_to_plane)),
        )

    def distance_xy(self, points_xy):
        """Distance from vertical lines through ``points_xy`` to the box, mm (0 where they meet it).

        The box is projected on the xy-plane (an annular sector); outside its azimuth range
        the nearest point lies on one of its two radial edges.

        Parameters
        ----------
        points_xy : array_like, shape (..., 2)
            Points in the xy-plane, mm.

        Returns
        -------
        numpy.ndarray
            Shape ``(...)``, mm.
        """
        p = np.asarray(points_xy, dtype=float)
        x, y = p[..., 0], p[..., 1]
        rho_lo, rho_hi = self.horizontal_extent()
        rho = np.hypot(x, y)
        radial = np.maximum(np.maximum(rho_lo - rho, rho - rho_hi), 0.0)
        if self.a0 is None:
            return radial
        half_width = 0.5 * (self.a1 - self.a0)
        within = np.abs(relative_azimuth(np.degrees(np.arctan2(y, x)), self._mid)) <= half_width
        gaps = []
        for edge in np.radians((self.a0, self.a1)):
            along = np.clip(x * math.cos(edge) + y * math.sin(edge), rho_lo, rho_hi)
            gaps.append(np.hypot(x - along * math.cos(edge), y - along * math.sin(edge)))
        return np.where(within, radial, np.minimum(*gaps))

    @property
    def _mid(self):
        return 0.5 * (self.a0 + self.a1)

    def contains_box(self, other):
        """True if ``other`` lies inside this box."""
        if not (
            self.r0 <= other.r0
            and other.r1 <= self.r1
            and self.e0 <= other.e0
            and other.e1 <= self.e1
        ):
            return False
        if self.a0 is None:
            return True
        if other.a0 is None:
            return False
        lo = self._mid + relative_azimuth(other.a0, self._mid)
        return self.a0 <= lo and lo + (other.a1 - other.a0) <= self.a1

    def contains(self, points_mm):
        """True for points (shape (…, 3), mm) inside the box."""
        p = np.asarray(points_mm, dtype=float)
        r = np.linalg.norm(p, axis=-1)
        e = np.degrees(np.arcsin(np.clip(p[..., 2] / np.where(r > 0, r, 1.0), -1.0, 1.0)))
        inside = (r >= self.r0) & (r <= self.r1) & (e >= self.e0) & (e <= self.e1)
        if self.a0 is not None:
            a = np.degrees(np.arctan2(p[..., 1], p[..., 0]))
            inside &= np.abs(relative_azimuth(a, self._mid)) <= 0.5 * (self.a1 - self.a0)
        return inside


def polar_directions(elevation_deg, azimuth_deg):
    """Unit vectors (cos e cos a, cos e sin a, sin e) of directions given by their angles.

    Parameters
    ----------
    elevation_deg, azimuth_deg : array_like
        Elevation e and azimuth a, degrees, broadcast together to shape P.

    Returns
    -------
    numpy.ndarray
        Shape P + (3,).
    """
    e, a = np.deg2rad(elevation_deg), np.deg2rad(azimuth_deg)
    return np.stack(
        np.broadcast_arrays(np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)), -1
    )


def polar_angles(points):
    """Elevation and azimuth of points about O, degrees.

    Parameters
    ----------
    points : numpy.ndarray, shape P + (3,)
        Points other than O, mm.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Elevation in [−90, 90] and azimuth in (−180, 180], shape P, degrees.
    """
    r = np.linalg.norm(points, axis=-1)
    elevation = np.degrees(np.arcsin(np.clip(points[..., 2] / r, -1.0, 1.0)))
    azimuth = np.degrees(np.arctan2(points[..., 1], points[..., 0]))
    return elevation, azimuth


def relative_azimuth(azimuth_deg, reference_deg):
    """Azimuth measured from a reference, wrapped to [−180, 180), degrees.

    Parameters
    ----------
    azimuth_deg : array_like
        Azimuths, degrees (any turn).
    reference_deg : float or array_like
        Reference azimuth, degrees.

    Returns
    -------
    float or numpy.ndarray
        ``azimuth − reference`` in [−180, 180), degrees.
    """
    return (azimuth_deg - reference_deg + 180.0) % 360.0 - 180.0


def distance_to_sphere(unit_vectors, centre, radius):
    """Distance from O along unit vectors to a sphere that holds O, mm.

    The far root of ``|t·u − c| = R``: ``t = u·c + sqrt((u·c)² − |c|² + R²)``.

    Parameters
    ----------
    unit_vectors : numpy.ndarray, shape P + (3,)
        Directions u from O (unit length).
    centre : numpy.ndarray, shape (3,)
        Sphere centre c, mm.
    radius : float
        Sphere radius R, mm (greater than ‖c‖).

    Returns
    -------
    numpy.ndarray
        Shape P, mm.
    """
    b = unit_vectors @ centre
    return b + np.sqrt(b * b - centre @ centre + radius * radius)


def drop_contained(boxes):
    """The boxes minus those lying inside another one (they cut nothing more).

    Parameters
    ----------
    boxes : sequence of PolarBox

    Returns
    -------
    tuple of PolarBox
        In their given order; of two equal boxes the first is kept.
    """

    def inside(i, b):  # within another box, and not the first of two equal ones
        return any(
            j != i and o.contains_box(b) and not (b.contains_box(o) and j > i)
            for j, o in enumerate(boxes)
        )

    return tuple(b for i, b in enumerate(boxes) if not inside(i, b))
