"""The one description of the parts (reflector_opt.cad._shapes), tested without build123d.

Every node says which points it holds (``contains``), exactly. Over every test design
(:mod:`tests.cad.designs`): the swept space the body is cut by holds the points of the
layout's boxes, no more and no less; and the meshes built from the description hold the
points it holds, except within the chord tolerance of its surface.
"""

import numpy as np
import pytest

from reflector_opt.cad import _shapes as shapes
from reflector_opt.cad import build_parts, plan_layout
from reflector_opt.cad._solids import SOLIDS, to_manifold
from reflector_opt.design._polar import PolarBox
from tests.cad.designs import designs

#: Chord tolerance of the meshes, mm.
TOLERANCE = 0.05
#: Every test design, by name.
DESIGNS = designs()


def _points(low, high, count, seed=0):
    """Random points, uniform in the box [low, high] (mm)."""
    rng = np.random.default_rng(seed)
    return rng.uniform(low, high, (count, 3))


@pytest.mark.parametrize("name", list(DESIGNS))
def test_both_forms_of_the_swept_space_hold_the_points_of_the_boxes_below_its_top(name):
    layout = plan_layout(DESIGNS[name])
    top = layout.body_top_z_mm + shapes.OVERSHOOT_MM
    space = shapes.swept_space(layout.keepouts, top)
    reach = max(box.r1 for box in layout.keepouts)
    points = _points((-reach, -reach, layout.body_bottom_z_mm - 1.0), (reach, reach, 12.0), 200_000)
    held = space.contains(points)
    in_boxes = np.logical_or.reduce([box.contains(points) for box in layout.keepouts])
    below = points[:, 2] <= top
    assert np.array_equal(held[below], in_boxes[below])  # exact below the top asked for
    assert np.array_equal(space.overlapping().contains(points), held)
    pieces = np.stack([piece.contains(points) for piece in space.pieces()])
    assert np.array_equal(pieces.any(axis=0), held)
    assert pieces.sum(axis=0).max() == 1  # the pieces meet only along planes (no point is in two)
    assert 0.05 < held.mean() < 0.5  # the sample reaches into the space and around it


def test_the_swept_space_stops_above_the_height_asked():
    box = PolarBox(7.2, 9.0, -30.0, 90.0, 10.0, 50.0)
    space = shapes.swept_space([box], 3.0)
    cap = np.degrees(np.arcsin(3.0 / 7.2))
    assert space.cap_deg == pytest.approx(cap)
    assert space.pieces() == (shapes.Revolved(7.2, ((-30.0, space.cap_deg, 9.0),), 10.0, 50.0),)
    points = _points((-9.0, -9.0, -9.0), (9.0, 9.0, 9.0), 50_000)
    below = points[:, 2] <= 3.0
    assert np.array_equal(space.contains(points)[below], box.contains(points)[below])
    assert not space.contains(points[points[:, 2] > 9.0 * np.sin(np.radians(cap))]).any()


def test_boxes_with_different_inner_radii_are_refused():
    boxes = [PolarBox(7.2, 9.0, 0.0, 90.0), PolarBox(7.1, 9.0, 0.0, 90.0)]
    with pytest.raises(ValueError, match="one inner radius"):
        shapes.swept_space(boxes, 3.0)


def _inside_mesh(solid, points):
    """Which points a manifold3d solid holds: an odd number of crossings up to far above."""
    crossings = [len(solid.ray_cast(tuple(p), (p[0] + 1e-3, p[1] + 2e-3, 100.0))) for p in points]
    return np.asarray(crossings) % 2 == 1


def _near_surface(shape, points, distance):
    """Points whose membership changes within ``distance`` along an axis."""
    held = shape.contains(points)
    steps = distance * np.vstack([np.eye(3), -np.eye(3)])
    return np.any([shape.contains(points + step) != held for step in steps], axis=0)


def _assert_mesh_holds(shape, mesh, count=6000, seed=0):
    """The mesh holds the points the shape holds, but for points within δ of its surface."""
    box = mesh.bounding_box()
    points = _points(np.subtract(box[:3], 0.5), np.add(box[3:], 0.5), count, seed)
    differ = _inside_mesh(mesh, points) != shape.contains(points)
    # a mesh within δ of the true surfaces misses only points within δ of them: a step of 2δ
    # along one of the axes crosses the surface from each
    stray = differ & ~_near_surface(shape, points, 2.0 * TOLERANCE)
    assert not stray.any(), points[stray][:5]


@pytest.mark.parametrize("name", list(DESIGNS))
def test_the_meshes_hold_the_points_the_description_holds(name):
    design = DESIGNS[name]
    layout = plan_layout(design)
    parts = build_parts(design, layout, TOLERANCE)
    outer_ring, inner_ring = shapes.bearing_shapes(layout, design)
    described = {
        "reflector": shapes.reflector_shape(layout),
        "body": shapes.body_shape(layout),
        "outer_ring": outer_ring,
        "inner_ring": inner_ring,
        "sensors": shapes.sensor_shape(layout),
    }
    for seed, solid in enumerate(SOLIDS):
        _assert_mesh_holds(described[solid], getattr(parts, solid), seed=seed)


def test_stepped_pieces_mesh_to_the_points_they_hold():
    # the form the STEP solids are built from, meshed: every stepped profile and azimuth range
    layout = plan_layout(DESIGNS["optimised"])
    pieces = shapes.swept_space(layout.keepouts, layout.body_top_z_mm + 1.0).pieces()
    assert max(len(piece.steps) for piece in pieces) >= 5
    for seed, piece in enumerate(pieces):
        _assert_mesh_holds(piece, to_manifold(piece, TOLERANCE), count=1000, seed=seed)
