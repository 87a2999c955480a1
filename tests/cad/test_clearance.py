"""Clearance proved over the workspace: the travel bound, radial extents, a planted contact,
no vertex of one printable part inside the other, and a workspace too wide refused."""

import math
from dataclasses import replace
from types import SimpleNamespace

import manifold3d as mf
import numpy as np
import pytest

from reflector_opt.cad import _background as background
from reflector_opt.cad import _export as export
from reflector_opt.cad import build_parts, check_collisions, plan_layout, to_trimesh
from reflector_opt.cad._clearance import radial_extent
from reflector_opt.cad._solids import pose, pose_matrix
from reflector_opt.design import Reflector, SensorPlacement, Workspace, default_design
from reflector_opt.model._geometry import rotation_x, rotation_y
from reflector_opt.util._errors import InputError

COARSE = 0.05

DESIGN = default_design().replace(
    reflector=Reflector(9.0, (0.0, 0.0, -1.2), 7.5),
    sensors=(
        SensorPlacement("S1", "NJL5901R-2", (10.0, 0.0, 0.0), (-1.0, 0.0, 0.0)),
        SensorPlacement("S2", "NJL5901R-2", (0.0, 10.0, 0.0), (0.0, -1.0, 0.0)),
    ),
)


def test_travel_bound_between_poses():
    # ‖Rx(a)Ry(g)p − Rx(a′)Ry(g′)p‖ ≤ ‖p‖(|Δg| + |Δa|), the bound the cells are proved with;
    # and for a point on the x axis turned by pitch alone it is met to first order.
    rng = np.random.default_rng(1)
    p = rng.normal(size=(500, 3)) * 10.0
    g, a = rng.uniform(-20, 20, 500), rng.uniform(-20, 20, 500)
    dg, da = rng.uniform(-3, 3, 500), rng.uniform(-3, 3, 500)
    r0 = rotation_x(a) @ rotation_y(g)
    r1 = rotation_x(a + da) @ rotation_y(g + dg)
    moved = np.linalg.norm(np.einsum("nij,nj->ni", r1 - r0, p), axis=1)
    bound = np.linalg.norm(p, axis=1) * np.radians(np.abs(dg) + np.abs(da))
    assert np.all(moved <= bound * (1 + 1e-12))
    chord = np.linalg.norm((rotation_y(0.1) - rotation_y(0.0)) @ [10.0, 0.0, 0.0])
    assert chord == pytest.approx(10.0 * math.radians(0.1), rel=1e-6)


def test_radial_extent_hand_values():
    import trimesh

    # A triangle in the plane z = 3 around the z axis: nearest point (0, 0, 3), farthest
    # corner (4, 0, 3) at 5; one wholly off-axis: nearest its corner (1, 1, 1) at √3.
    mesh = trimesh.Trimesh(
        [[4, 0, 3], [-2, 3, 3], [-2, -3, 3], [1, 1, 1], [2, 1, 1], [1, 2, 1]],
        [[0, 1, 2], [3, 4, 5]],
        process=False,
    )
    extent = radial_extent(mesh)
    assert extent[0] == pytest.approx([3.0, 5.0])
    assert extent[1] == pytest.approx([math.sqrt(3.0), math.sqrt(6.0)])


@pytest.fixture(scope="module")
def parts():
    return build_parts(DESIGN, plan_layout(DESIGN), COARSE)


def test_parts_proved_clear(parts):
    report = check_collisions(parts, DESIGN)
    assert report.collision_free and report.unproved_cells == 0
    assert 0.0 < report.proved_clearance_mm <= report.min_clearance_mm


def _overlap(parts, body, pitch, roll):
    return (pose(parts.reflector, pitch, roll) ^ body).volume()


@pytest.fixture(scope="module")
def planted(parts):
    """The parts with a small ball fixed to the body that the lowest point of a reflecting
    patch reaches only near the pose (3.75°, −11.25°), half-way between the 5 × 5 grid poses
    checked until now (steps of 7.5°): it dips 0.05 mm into the patch there and clears it
    at every grid pose."""
    target, radius, depth = (3.75, -11.25), 0.15, 0.05
    vertices = to_trimesh(parts.reflector).vertices
    lowest = vertices[np.argmin(vertices[:, 2])]
    outward = lowest - DESIGN.reflector.centre_mm
    outward /= np.linalg.norm(outward)
    centre = pose_matrix(*target)[:, :3] @ (lowest + (radius - depth) * outward)
    body = parts.body + mf.Manifold.sphere(radius, 48).translate(tuple(centre))
    return replace(parts, body=body), target


def test_contact_only_between_todays_grid_poses_is_found(parts, planted):
    planted, target = planted
    grid = np.linspace(-15.0, 15.0, 5)
    assert all(_overlap(parts, planted.body, g, a) == 0.0 for g in grid for a in grid)
    assert _overlap(parts, planted.body, *target) > 0.0

    report = check_collisions(planted, DESIGN)
    assert not report.collision_free and report.contact_pose_deg is not None
    g, a = report.contact_pose_deg
    # The pose reported is one where the parts do meet (so not one of the grid's).
    assert _overlap(parts, planted.body, g, a) > 0.0 and report.max_intersection_mm3 > 0.0
    assert report.problem.startswith(f"the reflector part and the body collide at pitch {g:g}°")


def test_export_refuses_the_planted_contact_and_writes_nothing(planted, monkeypatch, tmp_path):
    planted, _ = planted
    monkeypatch.setattr(export, "build_parts", lambda *args: planted)
    out = tmp_path / "out"
    with pytest.raises(InputError, match="the reflector part and the body collide at pitch"):
        export.export_parts(DESIGN, out, tolerance_mm=COARSE, preview=False)
    assert not out.exists()


def test_proof_shared_with_a_forked_process_equals_the_proof_in_one(parts, planted, monkeypatch):
    # Half the workspace's quarters are proved in a forked process; without fork the same
    # cells are proved in the caller, in the same order: the reports are identical.
    shared = [check_collisions(p, DESIGN) for p in (parts, planted[0])]
    monkeypatch.setattr(background.pools, "START_METHOD", "spawn")
    alone = [check_collisions(p, DESIGN) for p in (parts, planted[0])]
    assert [r.to_dict() for r in shared] == [r.to_dict() for r in alone]
    assert shared[0].collision_free and shared[0].problem is None
    assert not shared[1].collision_free and shared[1].problem is not None


def test_no_vertex_of_one_part_inside_the_other_at_the_corners(built):
    # Independent of manifold3d's booleans: trimesh point-in-solid tests.
    # Every third vertex where the two parts come near each other (beyond the bearing) is
    # tested; the body's are turned into the reflector's frame instead of posing the reflector.
    design, _, parts, _ = built
    body, reflector = to_trimesh(parts.body), to_trimesh(parts.reflector)
    body_near = body.vertices[np.linalg.norm(body.vertices, axis=1) < 10.5][::3]
    reflector_near = reflector.vertices[np.linalg.norm(reflector.vertices, axis=1) > 7.0][::3]
    for pitch in design.workspace.pitch_deg:
        for roll in design.workspace.roll_deg:
            rotation = rotation_x(roll) @ rotation_y(pitch)
            assert not body.contains(reflector_near @ rotation.T).any()
            assert not reflector.contains(body_near @ rotation).any()


def test_collision_check_can_fail(built):
    """The parts swept through ±40° (past the bearing's stop, so no design has it: the
    check is given the workspace alone) collide."""
    _, _, parts, _ = built
    wider = SimpleNamespace(workspace=Workspace((-40.0, 40.0), (-40.0, 40.0), 1.0))
    report = check_collisions(parts, wider)
    assert not report.collision_free and report.contact_pose_deg is not None
    assert report.max_intersection_mm3 > 0.0
