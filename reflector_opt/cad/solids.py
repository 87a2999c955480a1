"""The solids, built by constructive solid geometry on exact primitives with manifold3d.

Every curved primitive gets its segment count from the chord tolerance
(:mod:`reflector_opt.cad.tessellation`); spheres, cones and revolved profiles are combined by
boolean operations, so the result is a closed, consistently oriented 2-manifold by
construction. Parts are built at zero pose in the unit frame; :func:`pose` turns the rotating
ones by R = Rx(roll)·Ry(pitch) about O.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import manifold3d as mf
import numpy as np

from reflector_opt.cad.tessellation import circle_segments, sphere_segments
from reflector_opt.design.polar import PolarBox
from reflector_opt.model.geometry import rotation_x, rotation_y

__all__ = ["SOLIDS", "Parts", "build_parts", "polar_solid", "pose", "pose_matrix"]

#: Every solid of one joint, by name: the turning ones first, then the fixed ones.
SOLIDS = ("reflector", "inner_ring", "body", "outer_ring", "sensors")

OpType = mf.OpType


def _sphere(radius, tolerance, centre=(0.0, 0.0, 0.0)):
    return mf.Manifold.sphere(radius, sphere_segments(radius, tolerance)).translate(tuple(centre))


def _cylinder(radius, z0, z1, tolerance, centre_xy=(0.0, 0.0)):
    solid = mf.Manifold.cylinder(z1 - z0, radius, radius, circle_segments(radius, tolerance))
    return solid.translate((centre_xy[0], centre_xy[1], z0))


def _arc(radius, e0, e1, tolerance):
    """Points of an arc in the (ρ, z) half-plane from elevation e0 to e1 (degrees)."""
    n = max(1, math.ceil(circle_segments(radius, tolerance) * abs(e1 - e0) / 360.0))
    e = np.deg2rad(np.linspace(e0, e1, n + 1))
    return np.column_stack([radius * np.cos(e), radius * np.sin(e)])


def polar_solid(box, tolerance):
    """Solid of a :class:`~reflector_opt.design.polar.PolarBox` (spheres, cones, half-planes).

    The (ρ, z) profile — an annular sector between the radii and elevations — is revolved
    about z over the box's azimuth range (all around if it has none), with as many segments
    as the chord tolerance needs at the box's largest distance from the z axis: a partial
    turn gets its share of a full turn's segments.

    Parameters
    ----------
    box : PolarBox
    tolerance : float
        Chord tolerance, mm.

    Returns
    -------
    manifold3d.Manifold
    """
    e0, e1 = max(box.e0, -90.0), min(box.e1, 90.0)
    outer = _arc(box.r1, e0, e1, tolerance)
    inner = _arc(box.r0, e1, e0, tolerance) if box.r0 > 0 else np.zeros((1, 2))
    profile = np.vstack([outer, inner])
    profile[:, 0] = np.maximum(profile[:, 0], 0.0)
    section = mf.CrossSection([profile], mf.FillRule.EvenOdd)
    segments = circle_segments(max(box.horizontal_extent()[1], tolerance * 2.0), tolerance)
    if box.a0 is None:
        return mf.Manifold.revolve(section, segments)
    # manifold3d spreads the given segments over the revolved angle, not over a full turn.
    sweep = box.a1 - box.a0
    solid = mf.Manifold.revolve(section, max(1, math.ceil(segments * sweep / 360.0)), sweep)
    return solid.rotate((0.0, 0.0, box.a0))


def _sector_prism(a0, a1, reach, z0, z1):
    """All points with azimuth in [a0, a1] (degrees, a1 − a0 < 180) and z0 ≤ z ≤ z1."""
    a = np.deg2rad(np.linspace(a0, a1, 9))
    outline = np.vstack([[0.0, 0.0], np.column_stack([reach * np.cos(a), reach * np.sin(a)])])
    solid = mf.Manifold.extrude(mf.CrossSection([outline], mf.FillRule.EvenOdd), z1 - z0)
    return solid.translate((0.0, 0.0, z0))


def _box(frame, centre, size):
    """Box with edges along the rows of ``frame`` (3×3), centred at ``centre``."""
    matrix = np.column_stack([np.asarray(frame).T, np.asarray(centre, dtype=float)])
    return mf.Manifold.cube(tuple(size), center=True).transform(matrix.tolist())


def pose_matrix(pitch_deg, roll_deg):
    """The 3×4 affine matrix [R | 0] of R = Rx(roll)·Ry(pitch) (paper Eq 1)."""
    rotation = rotation_x(float(roll_deg)) @ rotation_y(float(pitch_deg))
    return np.column_stack([rotation, np.zeros(3)])


def pose(solid, pitch_deg, roll_deg):
    """A rotating solid turned to a pose about O."""
    return solid.transform(pose_matrix(pitch_deg, roll_deg).tolist())


def _tendon_holes(layout, tolerance):
    p = layout.params
    z0, z1 = layout.body_bottom_z_mm - 1.0, layout.flange_top_z_mm + 1.0
    holes = []
    for az in np.deg2rad(layout.tendon_azimuths_deg):
        xy = (p.tendon_radius_mm * math.cos(az), p.tendon_radius_mm * math.sin(az))
        holes.append(_cylinder(p.tendon_hole_diameter_mm / 2.0, z0, z1, tolerance, xy))
    return holes


def _channels(layout):
    """Vertical channel for the strip behind each sensor, through body and flange."""
    p = layout.params
    z0, z1 = layout.body_bottom_z_mm - 1.0, layout.flange_top_z_mm + 1.0
    cuts = []
    for m in layout.sensors:
        depth = layout.envelope_radius_mm + 1.0 - m.pad_distance_mm
        centre = m.pad_mm - m.frame[2] * depth / 2.0
        centre[2] = 0.5 * (z0 + z1)
        height = (z1 - z0) / abs(m.frame[1, 2])
        cuts.append(_box(m.frame, centre, (p.strip_width_mm, height, depth)))
    return cuts


def _windows(layout):
    p = layout.params
    g = 2.0 * p.sensor_pocket_clearance_mm
    cuts = []
    for m in layout.sensors:
        length = m.window_length_mm + 0.1
        centre = m.pad_mm + m.frame[2] * (length / 2.0 - 0.1)
        size = (p.sensor_width_mm + g, p.sensor_length_mm + g, length)
        cuts.append(_box(m.frame, centre, size))
    return cuts


def reflector_solid(layout, tolerance):
    """The reflector part at zero pose: reflecting patches, dome, neck, flange and shaft.

    Parameters
    ----------
    layout : reflector_opt.design.layout.Layout
    tolerance : float
        Chord tolerance, mm.

    Returns
    -------
    manifold3d.Manifold
    """
    p = layout.params
    reach = 4.0 * layout.envelope_radius_mm + 4.0 * layout.flange_top_z_mm
    outer = _sphere(layout.sphere_radius_mm, tolerance, layout.sphere_centre_mm)
    lid = _sphere(layout.lid_radius_mm, tolerance)
    below_band_top = polar_solid(PolarBox(0.0, reach, -90.0, layout.band_top_deg), tolerance)
    # Above the band a patch is kept only inside the dome, so that patch and dome overlap in
    # volume rather than touch along the band's top cone (which would leave a slit).
    patch_space = outer ^ (below_band_top + lid)
    pieces = []
    for patch in layout.patches:
        sector = _sector_prism(*patch.azimuth_deg, reach, -reach, reach)
        below = polar_solid(PolarBox(0.0, reach, -90.0, patch.elevation_deg[0]), tolerance)
        pieces.append((patch_space ^ sector) - below)
    pieces.append(lid - below_band_top)
    neck_top = layout.flange_z_mm + p.flange_thickness_mm / 2.0
    pieces.append(_cylinder(p.neck_radius_mm, 0.0, neck_top, tolerance))
    pieces.append(
        _cylinder(layout.envelope_radius_mm, layout.flange_z_mm, layout.flange_top_z_mm, tolerance)
    )
    solid = mf.Manifold.batch_boolean(pieces, OpType.Add) - _sphere(
        layout.inner_radius_mm, tolerance
    )
    solid = solid + _cylinder(layout.shaft_radius_mm, layout.shaft_bottom_z_mm, neck_top, tolerance)
    envelope = _cylinder(
        layout.envelope_radius_mm,
        layout.shaft_bottom_z_mm - 1.0,
        layout.flange_top_z_mm + 1.0,
        tolerance,
    )
    cuts = mf.Manifold.batch_boolean(
        _tendon_holes(layout, tolerance) + _channels(layout), OpType.Add
    )
    return (solid ^ envelope) - cuts


def _keepout_solid(keepouts, tolerance):
    """The union of the swept-space boxes, which all start at one inner radius r0.

    Each box is built from O outwards (inner radius 0) and the ball of radius r0 is removed
    from their union once: the same solid as the union of the boxes themselves, without
    many differently faceted copies of the sphere r0 for the booleans to intersect.
    """
    inner = {box.r0 for box in keepouts}
    if len(inner) != 1:
        return mf.Manifold.batch_boolean(
            [polar_solid(box, tolerance) for box in keepouts], OpType.Add
        )
    cones = [polar_solid(replace(box, r0=0.0), tolerance) for box in keepouts]
    return mf.Manifold.batch_boolean(cones, OpType.Add) - _sphere(inner.pop(), tolerance)


def body_solid(layout, tolerance):
    """The body at the joint: bearing seat, sensor windows and channels, tendon holes.

    The space every rotating solid sweeps over the workspace, plus the clearance, is removed
    from a cylinder of the unit's diameter (see :mod:`reflector_opt.design.layout`).

    Parameters
    ----------
    layout : reflector_opt.design.layout.Layout
    tolerance : float
        Chord tolerance, mm.

    Returns
    -------
    manifold3d.Manifold
    """
    c = layout.params.clearance_mm
    blank = _cylinder(
        layout.envelope_radius_mm, layout.body_bottom_z_mm, layout.body_top_z_mm, tolerance
    )
    pocket = _sphere(layout.bearing_pocket_radius_mm, tolerance).trim_by_plane(
        (0.0, 0.0, 1.0), layout.seat_z_mm
    )
    cuts = [
        pocket,
        _sphere(layout.swing_radius_mm + c, tolerance),
        _keepout_solid(layout.keepouts, tolerance),
        *_windows(layout),
        *_channels(layout),
        *_tendon_holes(layout, tolerance),
    ]
    return blank - mf.Manifold.batch_boolean(cuts, OpType.Add)


def bearing_solids(layout, design, tolerance):
    """The spherical bearing (not printed): fixed outer ring and rotating inner ring."""
    p, mech = layout.params, design.mechanics
    ball = _sphere(p.bearing_ball_diameter_mm / 2.0, tolerance)
    half_outer, half_inner = p.bearing_outer_width_mm / 2.0, p.bearing_inner_width_mm / 2.0
    outer_ring = _cylinder(mech.bearing_od_mm / 2.0, -half_outer, half_outer, tolerance) - ball
    bore = _cylinder(mech.bearing_bore_mm / 2.0, -half_inner - 1.0, half_inner + 1.0, tolerance)
    inner_ring = (
        (ball - bore).trim_by_plane((0, 0, 1), -half_inner).trim_by_plane((0, 0, -1), -half_inner)
    )
    return outer_ring, inner_ring


def sensor_solids(layout):
    """The sensor packages (not printed), behind each front face."""
    p = layout.params
    size = (p.sensor_width_mm, p.sensor_length_mm, p.sensor_depth_mm)
    boxes = [_box(m.frame, (m.front_mm + m.pad_mm) / 2.0, size) for m in layout.sensors]
    return mf.Manifold.batch_boolean(boxes, OpType.Add)


@dataclass(frozen=True)
class Parts:
    """All solids of one joint at zero pose.

    Attributes
    ----------
    reflector, body : manifold3d.Manifold
        The two printed parts.
    outer_ring, inner_ring : manifold3d.Manifold
        The bearing's rings (bought, not printed); the inner ring turns with the reflector.
    sensors : manifold3d.Manifold
        The sensor packages (fixed with the body).
    tolerance_mm : float
        Chord tolerance they were built with, mm.
    """

    reflector: mf.Manifold
    body: mf.Manifold
    outer_ring: mf.Manifold
    inner_ring: mf.Manifold
    sensors: mf.Manifold
    tolerance_mm: float

    @property
    def rotating(self):
        """Names of the solids that turn with the pose."""
        return ("reflector", "inner_ring")

    def posed(self, pitch_deg, roll_deg):
        """Every solid at a pose: the turning ones rotated by Rx(roll)·Ry(pitch) about O.

        Returns
        -------
        dict of str to manifold3d.Manifold
            Keys ``reflector``, ``inner_ring``, ``body``, ``outer_ring``, ``sensors``.
        """
        return {
            n: pose(getattr(self, n), pitch_deg, roll_deg)
            if n in self.rotating
            else getattr(self, n)
            for n in SOLIDS
        }


def build_parts(design, layout, tolerance_mm, parts=("reflector", "body")):
    """Build the solids of one joint.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    layout : reflector_opt.design.layout.Layout
    tolerance_mm : float
        Chord tolerance, mm.
    parts : iterable of str
        Printed parts to build (the others are left empty).

    Returns
    -------
    Parts
    """
    outer_ring, inner_ring = bearing_solids(layout, design, tolerance_mm)
    return Parts(
        reflector=reflector_solid(layout, tolerance_mm) if "reflector" in parts else mf.Manifold(),
        body=body_solid(layout, tolerance_mm) if "body" in parts else mf.Manifold(),
        outer_ring=outer_ring,
        inner_ring=inner_ring,
        sensors=sensor_solids(layout),
        tolerance_mm=tolerance_mm,
    )
