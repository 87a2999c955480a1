"""The solids as meshes: the description of :mod:`reflector_opt.cad._shapes` built with manifold3d.

Every curved primitive gets its segment count from the chord tolerance
(:mod:`reflector_opt.cad._tessellation`); spheres, cones and revolved profiles are combined by
boolean operations, so the result is a closed, consistently oriented 2-manifold by
construction. The STEP solids (:mod:`reflector_opt.cad._step`) are built from the same
description. Parts are built at zero pose in the unit frame; :func:`pose` turns the rotating
ones by R = Rx(roll)·Ry(pitch) about O.
"""

import math
from dataclasses import dataclass
from functools import singledispatch

import manifold3d as mf
import numpy as np

from reflector_opt.cad import _shapes as shapes
from reflector_opt.cad._tessellation import circle_segments, sphere_segments
from reflector_opt.model._geometry import rotation_x, rotation_y

#: Every solid of one joint, by name: the turning ones first, then the fixed ones.
SOLIDS = ("reflector", "inner_ring", "body", "outer_ring", "sensors")

OpType = mf.OpType


@singledispatch
def to_manifold(shape, tolerance):
    """The manifold3d solid of a node of :mod:`reflector_opt.cad._shapes`.

    Curved faces are inscribed polygons or geodesic spheres with as many segments as the
    chord tolerance needs (:mod:`reflector_opt.cad._tessellation`); unions, intersections
    and differences are manifold3d's booleans, so the result is a closed, consistently
    oriented 2-manifold.

    Parameters
    ----------
    shape : reflector_opt.cad._shapes node
    tolerance : float
        Chord tolerance, mm.

    Returns
    -------
    manifold3d.Manifold
    """
    raise TypeError(f"no mesh for {type(shape).__name__}")


@to_manifold.register
def _(shape: shapes.Sphere, tolerance):
    solid = mf.Manifold.sphere(shape.radius_mm, sphere_segments(shape.radius_mm, tolerance))
    return solid.translate(tuple(shape.centre_mm))


@to_manifold.register
def _(shape: shapes.Cylinder, tolerance):
    height = shape.z1_mm - shape.z0_mm
    segments = circle_segments(shape.radius_mm, tolerance)
    solid = mf.Manifold.cylinder(height, shape.radius_mm, shape.radius_mm, segments)
    return solid.translate((*shape.centre_xy_mm, shape.z0_mm))


@to_manifold.register
def _(shape: shapes.Block, tolerance):
    frame = np.asarray(shape.frame)
    matrix = np.column_stack([frame.T, np.asarray(shape.centre_mm)])
    return mf.Manifold.cube(shape.size_mm, center=True).transform(matrix.tolist())


@to_manifold.register
def _(shape: shapes.Sector, tolerance):
    # the wedge's arc lies far outside the parts: eight chords suffice
    a = np.deg2rad(np.linspace(shape.a0_deg, shape.a1_deg, 9))
    rim = shape.reach_mm * np.column_stack([np.cos(a), np.sin(a)])
    outline = mf.CrossSection([np.vstack([[0.0, 0.0], rim])], mf.FillRule.EvenOdd)
    solid = mf.Manifold.extrude(outline, shape.z1_mm - shape.z0_mm)
    return solid.translate((0.0, 0.0, shape.z0_mm))


def _arc(radius, e0, e1, tolerance, outside=False):
    """Points of an arc in the (ρ, z) half-plane from elevation e0 to e1 (degrees).

    Inscribed (the points on the arc) or, with ``outside``, circumscribed: the points at
    R / cos(Δ/2) for a step Δ, so that every chord touches the arc and the polygon holds it.
    """
    n = max(1, math.ceil(circle_segments(radius, tolerance) * abs(e1 - e0) / 360.0))
    e = np.deg2rad(np.linspace(e0, e1, n + 1))
    if outside:
        radius = radius / math.cos(0.5 * abs(e[1] - e[0]))
    return np.column_stack([radius * np.cos(e), radius * np.sin(e)])


def _turns(shape, tolerance):
    """Revolving segments of a Revolved and the angle they span, degrees.

    As many as the chord tolerance needs at its largest distance from the z axis; a partial
    turn gets its share of a full turn's segments (manifold3d spreads the given count over
    the revolved angle), at least 3 (manifold3d returns an empty solid for 1 or 2 segments
    over a few degrees).
    """
    segments = circle_segments(max(shape.horizontal_reach_mm(), tolerance * 2.0), tolerance)
    if shape.a0_deg is None:
        return segments, 360.0
    sweep = shape.a1_deg - shape.a0_deg
    return max(3, math.ceil(segments * sweep / 360.0)), sweep


def _revolve(shape, profile, count, sweep):
    """A (ρ, z) profile revolved about z over the shape's azimuth range."""
    profile[:, 0] = np.maximum(profile[:, 0], 0.0)
    section = mf.CrossSection([profile], mf.FillRule.EvenOdd)
    if shape.a0_deg is None:
        return mf.Manifold.revolve(section, count)
    return mf.Manifold.revolve(section, count, sweep).rotate((0.0, 0.0, shape.a0_deg))


@to_manifold.register
def _(shape: shapes.Revolved, tolerance):
    # The (ρ, z) profile: up the outer steps, down the inner arc (or O).
    outer = [_arc(radius, lo, hi, tolerance) for lo, hi, radius in shape.steps]
    e0, e1 = shape.elevation_range_deg
    inner = _arc(shape.r0_mm, e1, e0, tolerance) if shape.r0_mm > 0 else np.zeros((1, 2))
    return _revolve(shape, np.vstack([*outer, inner]), *_turns(shape, tolerance))


def _holding(wedge, tolerance):
    """A mesh that holds every point of a one-step Revolved reaching O (a box grown to O).

    The inscribed mesh of a revolved profile is, at each height z, the inscribed polygon of
    the profile's span [ρ_in(z), ρ_out(z)] there; it holds that exact annulus when ρ_out is
    stretched by 1 / cos(π/m) for m segments a turn and ρ_in is kept. So the arc is
    circumscribed and stretched; a radial edge is stretched where it bounds the span from
    outside (e0 ≥ 0 at the bottom, e1 ≤ 0 at the top) and kept, with a horizontal step out
    to the stretched arc, where it bounds it from inside.
    """
    if wedge.r0_mm > 0 or len(wedge.steps) != 1:
        raise ValueError("only a one-step profile reaching O is meshed to hold it")
    ((e0, e1, radius),) = wedge.steps
    count, sweep = _turns(wedge, tolerance)
    stretch = 1.0 / math.cos(math.radians(0.5 * sweep / count))
    arc = _arc(radius, e0, e1, tolerance, outside=True)
    kept = [arc[:1]] if e0 < 0.0 else [], [arc[-1:]] if e1 > 0.0 else []
    stretched = arc * (stretch, 1.0)
    profile = np.vstack([np.zeros((1, 2)), *kept[0], stretched, *kept[1]])
    return _revolve(wedge, profile, count, sweep)


@to_manifold.register
def _(shape: shapes.SweptSpace, tolerance):
    # A cut: its mesh must hold the whole exact space, or the body keeps material where the
    # turning parts pass (inscribed, up to a chord error of the profile plus one of the
    # revolution, ~2δ). The grown boxes are meshed to hold themselves at δ/2 each way, so
    # the cut lies between the exact space and about δ outside it; the ball it leaves out
    # is inscribed (a geodesic sphere), which only takes less away.
    space = shape.overlapping()
    grown = [_holding(box, tolerance / 2.0) for box in space.base.shapes]
    return mf.Manifold.batch_boolean(grown, OpType.Add) - _all(space.cuts, tolerance, OpType.Add)


@to_manifold.register
def _(shape: shapes.Slab, tolerance):
    solid = to_manifold(shape.shape, tolerance)
    if shape.z_min_mm is not None:
        solid = solid.trim_by_plane((0.0, 0.0, 1.0), shape.z_min_mm)
    if shape.z_max_mm is not None:
        solid = solid.trim_by_plane((0.0, 0.0, -1.0), -shape.z_max_mm)
    return solid


def _all(nodes, tolerance, op):
    return mf.Manifold.batch_boolean([to_manifold(n, tolerance) for n in nodes], op)


@to_manifold.register
def _(shape: shapes.Union, tolerance):
    return _all(shape.shapes, tolerance, OpType.Add)


@to_manifold.register
def _(shape: shapes.Intersection, tolerance):
    return _all(shape.shapes, tolerance, OpType.Intersect)


@to_manifold.register
def _(shape: shapes.Difference, tolerance):
    return to_manifold(shape.base, tolerance) - _all(shape.cuts, tolerance, OpType.Add)


def pose_matrix(pitch_deg, roll_deg):
    """The 3×4 affine matrix [R | 0] of R = Rx(roll)·Ry(pitch) (paper Eq 1)."""
    rotation = rotation_x(float(roll_deg)) @ rotation_y(float(pitch_deg))
    return np.column_stack([rotation, np.zeros(3)])


def pose(solid, pitch_deg, roll_deg):
    """A rotating solid turned to a pose about O."""
    return solid.transform(pose_matrix(pitch_deg, roll_deg).tolist())


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
    design : reflector_opt.design._design.Design
    layout : reflector_opt.design._layout.Layout
    tolerance_mm : float
        Chord tolerance, mm.
    parts : iterable of str
        Printed parts to build (the others are left empty).

    Returns
    -------
    Parts
    """
    outer_ring, inner_ring = shapes.bearing_shapes(layout, design)
    built = {
        name: to_manifold(describe(layout), tolerance_mm) if name in parts else mf.Manifold()
        for name, describe in shapes.PRINTED_SHAPES.items()
    }
    return Parts(
        **built,
        outer_ring=to_manifold(outer_ring, tolerance_mm),
        inner_ring=to_manifold(inner_ring, tolerance_mm),
        sensors=to_manifold(shapes.sensor_shape(layout), tolerance_mm),
        tolerance_mm=tolerance_mm,
    )
