"""The solids of one joint described once, as exact constructive solid geometry.

Every solid — the two printed parts, the bearing's rings and the sensor packages — is a tree
of exact primitives (:class:`Sphere`, :class:`Cylinder`, :class:`Block`, :class:`Sector`,
:class:`Revolved`) combined by :class:`Union`, :class:`Intersection`, :class:`Difference`
and :class:`Slab` (a cut by horizontal planes). The tree is pure geometry, derived from the
:class:`~reflector_opt.design._layout.Layout` alone; the meshes
(:func:`reflector_opt.cad._solids.to_manifold`, manifold3d) and the STEP solids
(:func:`reflector_opt.cad._step.to_solid`, build123d) are both built from it, node for node
(the one node each builds in its own form, the swept space, carries both forms; below), so
the two cannot describe different parts. Each node's ``contains`` states which points it
holds, exactly: the meaning both builders must reproduce, which the tests check without
either of them.

Frame and units as in :mod:`reflector_opt.design._layout`: lengths in mm, angles in degrees,
elevation from the xy-plane and azimuth from +x towards +y about O, parts at zero pose.

The body is cut by the space the turning parts sweep, which the layout gives as overlapping
:class:`~reflector_opt.design._polar.PolarBox` es with one inner radius (:class:`SweptSpace`).
The two libraries' booleans fail on opposite forms of it: OpenCASCADE on the boxes
themselves (their coincident spheres and the partial revolutions meeting on the z axis made
it return a body larger than its blank's cuts allow), manifold3d on pieces that only touch
(it leaves walls of no thickness between them). So the node carries two exact forms, each a
tree of the nodes above — :meth:`SweptSpace.pieces`, revolved stepped profiles that meet
only along planes, and :meth:`SweptSpace.overlapping`, the boxes grown to O, joined, less one
ball — and the tests check both against :meth:`SweptSpace.contains`.
"""

import itertools
import math
from dataclasses import dataclass

import numpy as np

from reflector_opt.design._polar import relative_azimuth

#: How far the cutters reach beyond the faces they cut through, so that no two faces
#: coincide, mm.
OVERSHOOT_MM = 1.0


def _points(points_mm):
    return np.asarray(points_mm, dtype=float)


def _within_azimuth(points, a0, a1):
    """True where the points' azimuth lies in [a0, a1] (degrees; True everywhere if None)."""
    if a0 is None:
        return np.ones(points.shape[:-1], dtype=bool)
    azimuth = np.degrees(np.arctan2(points[..., 1], points[..., 0]))
    mid = 0.5 * (a0 + a1)
    return np.abs(relative_azimuth(azimuth, mid)) <= 0.5 * (a1 - a0)


@dataclass(frozen=True)
class Sphere:
    """The ball ‖x − centre‖ ≤ radius (mm)."""

    radius_mm: float
    centre_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def contains(self, points_mm):
        """True for the points (shape (…, 3), mm) inside the solid."""
        offset = _points(points_mm) - np.asarray(self.centre_mm)
        return np.linalg.norm(offset, axis=-1) <= self.radius_mm


@dataclass(frozen=True)
class Cylinder:
    """A cylinder along z: distance from (x, y) = ``centre_xy_mm`` ≤ radius, z0 ≤ z ≤ z1 (mm)."""

    radius_mm: float
    z0_mm: float
    z1_mm: float
    centre_xy_mm: tuple[float, float] = (0.0, 0.0)

    def contains(self, points_mm):
        """True for the points (shape (…, 3), mm) inside the solid."""
        p = _points(points_mm)
        rho = np.hypot(p[..., 0] - self.centre_xy_mm[0], p[..., 1] - self.centre_xy_mm[1])
        return (rho <= self.radius_mm) & (p[..., 2] >= self.z0_mm) & (p[..., 2] <= self.z1_mm)


@dataclass(frozen=True)
class Block:
    """A box with edges along the rows of ``frame`` (an orthonormal 3×3), mm.

    Attributes
    ----------
    frame : tuple of three (float, float, float)
        Unit vectors along the box's width, length and depth.
    centre_mm : (float, float, float)
    size_mm : (float, float, float)
        Width, length and depth, mm.
    """

    frame: tuple[tuple[float, float, float], ...]
    centre_mm: tuple[float, float, float]
    size_mm: tuple[float, float, float]

    @classmethod
    def along(cls, frame, centre_mm, size_mm):
        """A block from array-likes (frame rows, centre and size in mm)."""
        frame = tuple(tuple(float(v) for v in row) for row in np.asarray(frame, dtype=float))
        return cls(frame, tuple(float(v) for v in centre_mm), tuple(float(v) for v in size_mm))

    def contains(self, points_mm):
        """True for the points (shape (…, 3), mm) inside the solid."""
        local = (_points(points_mm) - np.asarray(self.centre_mm)) @ np.asarray(self.frame).T
        return np.all(np.abs(local) <= 0.5 * np.asarray(self.size_mm), axis=-1)


@dataclass(frozen=True)
class Sector:
    """The points with azimuth in [a0, a1] (a1 − a0 < 180°), within ``reach_mm`` of the z axis
    and with z0 ≤ z ≤ z1 (mm): a wedge standing on the z axis."""

    a0_deg: float
    a1_deg: float
    reach_mm: float
    z0_mm: float
    z1_mm: float

    def contains(self, points_mm):
        """True for the points (shape (…, 3), mm) inside the solid."""
        p = _points(points_mm)
        inside = _within_azimuth(p, self.a0_deg, self.a1_deg)
        inside &= np.hypot(p[..., 0], p[..., 1]) <= self.reach_mm
        return inside & (p[..., 2] >= self.z0_mm) & (p[..., 2] <= self.z1_mm)


@dataclass(frozen=True)
class Revolved:
    """A stepped profile about O revolved about z over an azimuth range.

    The points at distance r from O, elevation e and azimuth a with ``r0 ≤ r ≤ R`` for a step
    ``(e_lo, e_hi, R)`` with ``e_lo ≤ e ≤ e_hi``, and a0 ≤ a ≤ a1. The steps follow each other
    upwards without gaps; in the (ρ, z) half-plane the profile is bounded by circular arcs
    about O (the inner one of radius r0, or O itself when r0 = 0) and radial lines.

    Attributes
    ----------
    r0_mm : float
        Inner radius, mm (0: the profile reaches O).
    steps : tuple of (float, float, float)
        ``(e_lo, e_hi, R)``: elevations in degrees within [−90, 90], radius in mm (> r0).
    a0_deg, a1_deg : float or None
        Azimuth range, degrees (a1 − a0 < 360); both None for every azimuth.
    """

    r0_mm: float
    steps: tuple[tuple[float, float, float], ...]
    a0_deg: float | None = None
    a1_deg: float | None = None

    @property
    def elevation_range_deg(self):
        """Lowest and highest elevation of the profile, degrees."""
        return self.steps[0][0], self.steps[-1][1]

    def horizontal_reach_mm(self):
        """Largest distance of the solid's points from the z axis, mm."""
        # at each step's elevation nearest to 0
        return max(r * math.cos(math.radians(min(max(0.0, lo), hi))) for lo, hi, r in self.steps)

    def contains(self, points_mm):
        """True for the points (shape (…, 3), mm) inside the solid."""
        p = _points(points_mm)
        r = np.linalg.norm(p, axis=-1)
        e = np.degrees(np.arcsin(np.clip(p[..., 2] / np.where(r > 0, r, 1.0), -1.0, 1.0)))
        outer = np.zeros(r.shape, dtype=bool)
        for lo, hi, radius in self.steps:
            outer |= (e >= lo) & (e <= hi) & (r <= radius)
        return outer & (r >= self.r0_mm) & _within_azimuth(p, self.a0_deg, self.a1_deg)


@dataclass(frozen=True)
class Slab:
    """The points of ``shape`` with z_min ≤ z ≤ z_max (mm; None: unbounded that way)."""

    shape: object
    z_min_mm: float | None = None
    z_max_mm: float | None = None

    def contains(self, points_mm):
        """True for the points (shape (…, 3), mm) inside the solid."""
        p = _points(points_mm)
        inside = self.shape.contains(p)
        if self.z_min_mm is not None:
            inside &= p[..., 2] >= self.z_min_mm
        if self.z_max_mm is not None:
            inside &= p[..., 2] <= self.z_max_mm
        return inside


@dataclass(frozen=True)
class Union:
    """The points in any of ``shapes``."""

    shapes: tuple

    def contains(self, points_mm):
        """True for the points (shape (…, 3), mm) inside the solid."""
        return np.logical_or.reduce([s.contains(points_mm) for s in self.shapes])


@dataclass(frozen=True)
class Intersection:
    """The points in every one of ``shapes``."""

    shapes: tuple

    def contains(self, points_mm):
        """True for the points (shape (…, 3), mm) inside the solid."""
        return np.logical_and.reduce([s.contains(points_mm) for s in self.shapes])


@dataclass(frozen=True)
class Difference:
    """The points of ``base`` in none of ``cuts``."""

    base: object
    cuts: tuple

    def contains(self, points_mm):
        """True for the points (shape (…, 3), mm) inside the solid."""
        cut = np.logical_or.reduce([s.contains(points_mm) for s in self.cuts])
        return self.base.contains(points_mm) & ~cut


# --- the swept space --------------------------------------------------------------------------


def _covering(boxes, azimuth_deg):
    """Indices of the boxes whose azimuth range holds ``azimuth_deg``."""
    a = math.radians(azimuth_deg)
    direction = np.array([math.cos(a), math.sin(a), 0.0])
    return tuple(i for i, b in enumerate(boxes) if _within_azimuth(direction, b.a0, b.a1))


def _azimuth_runs(boxes):
    """The azimuth ranges over which the same boxes overlap, as ``(a0, a1, indices)``.

    The ranges follow each other around the circle (a1 of one is a0 of the next, degrees);
    neighbours over the same boxes are merged. A single range over every azimuth has
    ``a0 = a1 = None``.
    """
    ends = sorted({a % 360.0 for b in boxes if b.a0 is not None for a in (b.a0, b.a1)})
    if not ends:
        return [(None, None, tuple(range(len(boxes))))]
    runs = []
    for lo, hi in zip(ends, [*ends[1:], ends[0] + 360.0], strict=True):
        cover = _covering(boxes, 0.5 * (lo + hi))
        if runs and runs[-1][2] == cover:
            runs[-1] = (runs[-1][0], hi, cover)
        else:
            runs.append((lo, hi, cover))
    if len(runs) > 1 and runs[0][2] == runs[-1][2]:
        lo, _, cover = runs.pop()
        runs[0] = (lo - 360.0, runs[0][1], cover)
    if len(runs) == 1:
        return [(None, None, runs[0][2])]
    return runs


def _skyline(boxes, cap_deg):
    """The outer radius over elevation of boxes about O, cut at ``cap_deg``.

    Returns
    -------
    list of list of (float, float, float)
        Runs of contiguous steps ``(e_lo, e_hi, R)`` (degrees, mm): R is the largest outer
        radius of the boxes over that elevation range; a run ends where no box reaches.
    """
    edges = sorted({min(max(e, -90.0), cap_deg) for b in boxes for e in (b.e0, b.e1)})
    runs = []
    for lo, hi in itertools.pairwise(edges):
        mid = 0.5 * (lo + hi)
        radii = [b.r1 for b in boxes if b.e0 <= mid <= b.e1]
        if not radii:
            continue
        radius = max(radii)
        if not runs or runs[-1][-1][1] != lo:
            runs.append([(lo, hi, radius)])
        elif runs[-1][-1][2] == radius:
            runs[-1][-1] = (runs[-1][-1][0], hi, radius)
        else:
            runs[-1].append((lo, hi, radius))
    return runs


@dataclass(frozen=True)
class SweptSpace:
    """The union of polar boxes about O that share their inner radius, below an elevation.

    The points of any of ``boxes`` whose elevation is at most ``cap_deg``. Two exact forms
    of it, each a tree of the nodes above, serve the two builders: :meth:`pieces` (no two
    pieces overlap) and :meth:`overlapping` (no two pieces merely touch).

    Attributes
    ----------
    boxes : tuple of reflector_opt.design._polar.PolarBox
        All with the same inner radius r0 > 0.
    cap_deg : float
        Highest elevation, degrees.
    """

    boxes: tuple
    cap_deg: float

    @property
    def r0_mm(self):
        """The boxes' common inner radius, mm."""
        return self.boxes[0].r0

    def contains(self, points_mm):
        """True for the points (shape (…, 3), mm) inside the solid."""
        p = _points(points_mm)
        inside = np.logical_or.reduce([box.contains(p) for box in self.boxes])
        r = np.linalg.norm(p, axis=-1)
        sine = np.divide(p[..., 2], r, out=np.zeros_like(r), where=r > 0)
        return inside & (sine <= math.sin(math.radians(self.cap_deg)))

    def pieces(self):
        """The space as stepped profiles revolved over azimuth ranges that only touch.

        The azimuth circle is cut where any box starts or ends; over each range the boxes
        present make one stepped profile (the largest outer radius over each elevation),
        revolved over that range. The pieces share no curved face and meet only along planes
        through the z axis (OpenCASCADE's booleans fail on the boxes themselves, whose
        coincident spheres and cones it cannot resolve).

        Returns
        -------
        tuple of Revolved
        """
        pieces = []
        for a0, a1, cover in _azimuth_runs(self.boxes):
            for steps in _skyline([self.boxes[i] for i in cover], self.cap_deg):
                pieces.append(Revolved(self.r0_mm, tuple(steps), a0, a1))
        return tuple(pieces)

    def overlapping(self):
        """The space as the boxes grown inwards to O, joined, less the ball of radius r0.

        The boxes overlap in volume rather than touch along faces (manifold3d joins solids
        that meet along a face only where the two faces' vertices coincide), and the ball is
        one solid instead of one faceted copy of it per box.

        Returns
        -------
        Difference
        """
        grown = tuple(
            Revolved(0.0, ((max(b.e0, -90.0), min(b.e1, self.cap_deg), b.r1),), b.a0, b.a1)
            for b in self.boxes
            if b.e0 < self.cap_deg
        )
        return Difference(Union(grown), (Sphere(self.r0_mm),))


def swept_space(keepouts, z_max_mm):
    """The union of the swept-space boxes, exact below a height.

    Every point above the elevation asin(z_max / r0) lies above ``z_max_mm``, so the space
    stops there (:class:`SweptSpace`): that changes nothing below ``z_max_mm`` and keeps
    partial revolutions off the z axis, where they would meet in one edge.

    Parameters
    ----------
    keepouts : sequence of reflector_opt.design._polar.PolarBox
        Boxes with one inner radius r0 (as the layout's).
    z_max_mm : float
        Height below which the space must be exact, mm.

    Returns
    -------
    SweptSpace

    Raises
    ------
    ValueError
        The boxes do not share one inner radius.
    """
    r0 = keepouts[0].r0
    if any(box.r0 != r0 for box in keepouts):
        raise ValueError("the swept-space boxes must share one inner radius")
    cap = 90.0 if z_max_mm >= r0 else math.degrees(math.asin(max(z_max_mm, 0.0) / r0))
    return SweptSpace(tuple(keepouts), cap)


# --- the parts ---------------------------------------------------------------------------------


def _tendon_holes(layout):
    """The three tendon holes, through body and flange."""
    p = layout.params
    z0 = layout.body_bottom_z_mm - OVERSHOOT_MM
    z1 = layout.flange_top_z_mm + OVERSHOOT_MM
    radius = p.tendon_hole_diameter_mm / 2.0
    return tuple(
        Cylinder(
            radius, z0, z1, (p.tendon_radius_mm * math.cos(a), p.tendon_radius_mm * math.sin(a))
        )
        for a in np.deg2rad(layout.tendon_azimuths_deg)
    )


def _channels(layout):
    """The vertical channel for the strip behind each sensor, through body and flange.

    The channel runs from the pad plane (normal to the optical axis a) out through the
    envelope. With the axis tilted out of the disk plane its outer face, a plane normal to a,
    meets the envelope cylinder at ``R·|a_xy| − z·a_z`` along a, which changes with the height
    z: the channel is cut deep enough for the farthest of its ends (else a wedge of body,
    thinning to nothing, would stay between its outer face and the envelope).
    """
    p = layout.params
    z0 = layout.body_bottom_z_mm - OVERSHOOT_MM
    z1 = layout.flange_top_z_mm + OVERSHOOT_MM
    cuts = []
    for m in layout.sensors:
        a = m.frame[2]
        reach = layout.envelope_radius_mm * math.hypot(a[0], a[1]) + max(-z0 * a[2], -z1 * a[2])
        depth = max(layout.envelope_radius_mm, reach) + OVERSHOOT_MM - m.pad_distance_mm
        centre = m.pad_mm - m.frame[2] * depth / 2.0
        # to mid-height along the strip, not straight up: a vertical shift would move the
        # floor off the pad plane by a_z per mm (into the wall behind the channel)
        centre = centre + m.frame[1] * (0.5 * (z0 + z1) - centre[2]) / m.frame[1, 2]
        height = (z1 - z0) / abs(m.frame[1, 2])
        cuts.append(Block.along(m.frame, centre, (p.strip_width_mm, height, depth)))
    return tuple(cuts)


def _windows(layout):
    """The window in front of each sensor, from its pad into the cavity.

    It holds the package and lets the light through: a block across the strip, along it and
    along the optical axis a. Along an axis tilted up its top would rise past the package's
    face and thin the wall above, which the layout measures at the face
    (:func:`~reflector_opt.design._layout.window_wall_mm`): there it is cut level with the
    top of the face.
    """
    p = layout.params
    g = 2.0 * p.sensor_pocket_clearance_mm
    cuts = []
    for m in layout.sensors:
        length = m.window_length_mm + 0.1
        centre = m.pad_mm + m.frame[2] * (length / 2.0 - 0.1)
        size = (p.sensor_width_mm + g, p.sensor_length_mm + g, length)
        window = Block.along(m.frame, centre, size)
        if m.frame[2][2] > 0.0:
            top = m.front_mm[2] + 0.5 * size[1] * m.frame[1][2]
            window = Slab(window, z_max_mm=float(top))
        cuts.append(window)
    return tuple(cuts)


def reflector_shape(layout):
    """The reflector part at zero pose: reflecting patches, dome, neck, flange and shaft.

    Each patch is the reflecting sphere (radius r_s about s0) within its azimuth range,
    above its lowest elevation and below the band's top (above it, inside the dome, so that
    patch and dome overlap in volume rather than touch along a cone). The dome, neck and
    flange are joined to the patches, the ball of the inner radius is removed, the shaft is
    added, and the whole is cut to the envelope and by the tendon holes and strip channels.

    Parameters
    ----------
    layout : reflector_opt.design._layout.Layout

    Returns
    -------
    Difference
    """
    p = layout.params
    reach = 4.0 * layout.envelope_radius_mm + 4.0 * layout.flange_top_z_mm
    outer = Sphere(layout.sphere_radius_mm, layout.sphere_centre_mm)
    lid = Sphere(layout.lid_radius_mm)
    below_band_top = Revolved(0.0, ((-90.0, layout.band_top_deg, reach),))
    patch_space = Intersection((outer, Union((below_band_top, lid))))
    pieces = []
    for patch in layout.patches:
        sector = Sector(*patch.azimuth_deg, reach, -reach, reach)
        below = Revolved(0.0, ((-90.0, patch.elevation_deg[0], reach),))
        pieces.append(Difference(Intersection((patch_space, sector)), (below,)))
    pieces.append(Difference(lid, (below_band_top,)))
    neck_top = layout.flange_z_mm + p.flange_thickness_mm / 2.0
    pieces.append(Cylinder(p.neck_radius_mm, 0.0, neck_top))
    pieces.append(Cylinder(layout.envelope_radius_mm, layout.flange_z_mm, layout.flange_top_z_mm))
    hollow = Difference(Union(tuple(pieces)), (Sphere(layout.inner_radius_mm),))
    solid = Union((hollow, Cylinder(layout.shaft_radius_mm, layout.shaft_bottom_z_mm, neck_top)))
    # From below the body's bottom: a patch may hang below the shaft's end (a unit on a narrow
    # bearing, its sphere low), and a floor there would cut its shell thin.
    envelope = Cylinder(
        layout.envelope_radius_mm,
        layout.body_bottom_z_mm - OVERSHOOT_MM,
        layout.flange_top_z_mm + OVERSHOOT_MM,
    )
    return Difference(Intersection((solid, envelope)), _tendon_holes(layout) + _channels(layout))


def body_shape(layout):
    """The body at the joint: bearing seat, sensor windows and channels, tendon holes.

    A cylinder of the unit's diameter less the bearing pocket (the ball of
    ``bearing_pocket_radius_mm`` above the seat), the ball the inner ring and shaft end stay
    within (plus clearance), the space every turning solid sweeps over the workspace
    (:func:`swept_space`), and the windows, channels and tendon holes.

    Parameters
    ----------
    layout : reflector_opt.design._layout.Layout

    Returns
    -------
    Difference
    """
    c = layout.params.clearance_mm
    blank = Cylinder(layout.envelope_radius_mm, layout.body_bottom_z_mm, layout.body_top_z_mm)
    cuts = (
        Slab(Sphere(layout.bearing_pocket_radius_mm), z_min_mm=layout.seat_z_mm),
        Sphere(layout.swing_radius_mm + c),
        swept_space(layout.keepouts, layout.body_top_z_mm + OVERSHOOT_MM),
        *_windows(layout),
        *_channels(layout),
        *_tendon_holes(layout),
    )
    return Difference(blank, cuts)


def bearing_shapes(layout, design):
    """The spherical bearing (bought, not printed): the fixed outer and turning inner ring.

    Parameters
    ----------
    layout : reflector_opt.design._layout.Layout
    design : reflector_opt.design._design.Design
        Its ``mechanics`` give the bore and outer diameter, mm.

    Returns
    -------
    (Difference, Slab)
        Outer ring, inner ring.
    """
    p, mech = layout.params, design.mechanics
    ball = Sphere(p.bearing_ball_diameter_mm / 2.0)
    half_outer, half_inner = p.bearing_outer_width_mm / 2.0, p.bearing_inner_width_mm / 2.0
    outer_ring = Difference(Cylinder(mech.bearing_od_mm / 2.0, -half_outer, half_outer), (ball,))
    bore = Cylinder(
        mech.bearing_bore_mm / 2.0, -half_inner - OVERSHOOT_MM, half_inner + OVERSHOOT_MM
    )
    inner_ring = Slab(Difference(ball, (bore,)), -half_inner, half_inner)
    return outer_ring, inner_ring


def sensor_shape(layout):
    """The sensor packages (bought, not printed), each behind its front face.

    Parameters
    ----------
    layout : reflector_opt.design._layout.Layout

    Returns
    -------
    Union
    """
    p = layout.params
    size = (p.sensor_width_mm, p.sensor_length_mm, p.sensor_depth_mm)
    return Union(
        tuple(Block.along(m.frame, (m.front_mm + m.pad_mm) / 2.0, size) for m in layout.sensors)
    )


#: The description of each printed part, by name, from a layout.
PRINTED_SHAPES = {"reflector": reflector_shape, "body": body_shape}
