"""The Eq 3 ray check of an exported reflector mesh (cad.verification)."""

import numpy as np
import pytest
import trimesh

from reflector_opt.cad import build_parts, plan_layout, to_trimesh, verify_distances
from reflector_opt.design import default_design
from reflector_opt.model._geometry import rotation_x, rotation_y, sensor_distance
from tests.cad.designs import COARSE, DESIGN_A, DESIGN_B, DESIGN_C


@pytest.mark.parametrize("design", [default_design(), DESIGN_A, DESIGN_B, DESIGN_C], ids="DABC")
def test_rays_hit_at_the_eq3_distance(design):
    layout = plan_layout(design)
    mesh = to_trimesh(build_parts(design, layout, COARSE, parts=("reflector",)).reflector)
    check = verify_distances(mesh, design, COARSE)
    assert check.passed, check
    assert check.rays == 98 and check.missed == 0
    assert 0.0 < check.mean_error_mm < COARSE  # an inscribed mesh lies inside the sphere


def test_ray_check_on_an_actually_posed_mesh():
    design, pitch, roll = DESIGN_A, 15.0, -15.0
    mesh = to_trimesh(
        build_parts(design, plan_layout(design), COARSE, parts=("reflector",)).reflector
    )
    posed = mesh.copy()
    transform = np.eye(4)
    transform[:3, :3] = rotation_x(roll) @ rotation_y(pitch)
    posed.apply_transform(transform)
    s1 = transform[:3, :3] @ np.asarray(design.reflector.centre_mm)
    f = design.positions_mm
    directions = (s1 - f) / np.linalg.norm(s1 - f, axis=1, keepdims=True)
    hits, index_ray, _ = posed.ray.intersects_location(f, directions, multiple_hits=False)
    distance = np.linalg.norm(hits - f[index_ray], axis=1)
    expected = sensor_distance(
        f, design.reflector.centre_mm, design.reflector.radius_mm, pitch, roll
    )
    assert sorted(index_ray) == [0, 1]
    assert np.all(np.abs(distance - expected[index_ray]) <= COARSE)
    rotated_ray = verify_distances(mesh, design, COARSE, [pitch], [roll])
    assert rotated_ray.max_error_mm == pytest.approx(
        np.abs(distance - expected[index_ray]).max(), abs=1e-9
    )


def test_ray_check_detects_a_wrong_surface():
    mesh = to_trimesh(
        build_parts(DESIGN_A, plan_layout(DESIGN_A), COARSE, parts=("reflector",)).reflector
    )
    check = verify_distances(mesh, DESIGN_B, COARSE)  # B's sphere is 0.2 mm larger
    assert not check.passed and check.max_error_mm > 0.1


def test_a_mesh_no_ray_hits_fails_the_check_instead_of_crashing():
    """Export with cad.tendon_hole_diameter_mm = 20 (holes that cut the part away) ended
    in an internal error: no ray hit, and the empty hits did not broadcast."""

    far = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    far.apply_translation((500.0, 500.0, 500.0))
    check = verify_distances(far, DESIGN_A, COARSE)
    assert check.rays == 98 and check.missed == 98 and not check.passed
    assert check.max_error_mm == float("inf")
