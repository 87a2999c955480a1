"""Tessellation: segments per circle and sphere for a chord tolerance, a mesh's deviation."""

import math

import manifold3d as mf
import numpy as np
import pytest

from reflector_opt.cad import circle_segments, sphere_segments, to_trimesh
from reflector_opt.cad._tessellation import sphere_deviation_mm
from reflector_opt.util._errors import InputError


@pytest.mark.parametrize("segments", [circle_segments, sphere_segments])
def test_a_tolerance_too_fine_for_a_mesh_is_refused(segments):
    assert segments(11.0, 0.001) <= 1024
    for tolerance in (1e-6, 1e-300):
        with pytest.raises(InputError, match="segments per circle, more than the limit of 1,024"):
            segments(11.0, tolerance)


def test_circle_segments_hand_value():
    # R = 9 mm, δ = 0.01 mm, x = δ/R: arccos(1 − x) ≈ sqrt(2x)(1 + x/12) = 0.0471448 rad,
    # π / that = 66.64 → 67, rounded up to a multiple of 4: 68.
    assert math.acos(1 - 0.01 / 9) == pytest.approx(0.0471448, abs=1e-7)
    assert circle_segments(9.0, 0.01) == 68
    # 68 segments keep the sagitta within δ; 64 (the next multiple of 4 down) would not.
    assert 9.0 * (1 - math.cos(math.pi / 68)) <= 0.01 < 9.0 * (1 - math.cos(math.pi / 64))


@pytest.mark.parametrize(
    ("radius", "tolerance"), [(9.0, 0.01), (9.0, 0.05), (7.5, 0.02), (3.0, 0.01)]
)
def test_sphere_mesh_deviation_within_tolerance(radius, tolerance):
    mesh = to_trimesh(mf.Manifold.sphere(radius, sphere_segments(radius, tolerance)))
    inside, outside = sphere_deviation_mm(mesh.vertices, mesh.faces, (0, 0, 0), radius)
    assert outside < 1e-9
    assert 0.5 * tolerance < inside <= tolerance  # within δ, and not needlessly fine
    # Independent path: densely sampled points of every triangle (barycentric grid).
    k = 10
    bary = np.array(
        [(i / k, j / k, 1 - (i + j) / k) for i in range(k + 1) for j in range(k + 1 - i)]
    )
    points = np.einsum("bk,tkd->tbd", bary, mesh.triangles)
    assert radius - np.linalg.norm(points, axis=-1).min() == pytest.approx(inside, rel=0.02)
