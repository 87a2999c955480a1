"""Paper Eqs 1–3 and the optical-axis intersection, against hand values and independent paths."""

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.optimize import minimize

from reflector_opt.model._geometry import (
    rotate_centre,
    rotation_x,
    rotation_y,
    sensor_distance,
    sensor_frames,
    surface_normal,
    trace_axis,
)
from reflector_opt.util._errors import CollisionError

angles = st.floats(-60, 60, allow_nan=False)


def test_rotation_matrices_hand_values():
    c, s = np.cos(np.deg2rad(30)), np.sin(np.deg2rad(30))
    assert_allclose(rotation_y(30), [[c, 0, s], [0, 1, 0], [-s, 0, c]])
    assert_allclose(rotation_x(30), [[1, 0, 0], [0, c, -s], [0, s, c]])
    # right-handed, active: +90° pitch takes x to −z, +90° roll takes y to +z
    assert_allclose(rotation_y(90) @ [1, 0, 0], [0, 0, -1], atol=1e-15)
    assert_allclose(rotation_x(90) @ [0, 1, 0], [0, 0, 1], atol=1e-15)


def test_rotate_centre_hand_value():
    # s0 = (0, 0, -2): pitch 30° then roll 90°.
    # Ry(30) s0 = (-2 sin30, 0, -2 cos30) = (-1, 0, -1.7320508)
    # Rx(90) (x, y, z) = (x, -z, y) = (-1, 1.7320508, 0)
    assert_allclose(rotate_centre([0, 0, -2], 30, 90), [-1, np.sqrt(3), 0], atol=1e-12)


@given(pitch=angles, roll=angles)
def test_rotate_centre_matches_matrix_product(pitch, roll):
    s0 = np.array([0.3, -0.7, -1.9])
    assert_allclose(rotate_centre(s0, pitch, roll), rotation_x(roll) @ rotation_y(pitch) @ s0)


def test_sensor_distance_hand_values():
    # f = (9.5, 0, 0), s0 = (0, 0, -2), r_s = 7.5:
    # zero pose |p| = sqrt(9.5² + 2²) = 9.7082, d = 2.2082
    # pitch 15°: s1 = (-2 sin15, 0, -2 cos15), |p|² = 94.25 + 38 sin15 = 104.0850
    d = sensor_distance([9.5, 0, 0], [0, 0, -2], 7.5, [0, 15, -15], 0)
    assert_allclose(
        d, [np.sqrt(94.25) - 7.5, np.sqrt(104.0850) - 7.5, np.sqrt(84.4150) - 7.5], atol=2e-5
    )


def test_sensor_distance_broadcasting_shapes():
    sensors = np.array([[10.0, 0, 0], [0, 10.0, 0]])
    pitch, roll = np.linspace(-15, 15, 7)[:, None], np.linspace(-15, 15, 5)[None, :]
    d = sensor_distance(sensors, [0, 0, -1.5], 9.0, pitch, roll)
    assert d.shape == (7, 5, 2)
    # one sensor at a time, one pose at a time, gives the same numbers
    assert_allclose(d[3, 1, 1], sensor_distance(sensors[1], [0, 0, -1.5], 9.0, 0.0, -7.5))
    # a (2, 2, 3) block of sensors gives pose shape + (2, 2)
    block = np.stack([sensors, sensors + np.array([0, 0, 0.5])])
    assert sensor_distance(block, [0, 0, -1.5], 9.0, pitch, roll).shape == (7, 5, 2, 2)


def test_collision_is_reported_not_negative():
    with pytest.raises(CollisionError, match="inside the reflector sphere at 1 pose"):
        sensor_distance([7.0, 0, 0], [0, 0, -2], 7.0, [0, -30], 0)  # −30°: |p| = 6.24 < r_s
    d = sensor_distance([7.0, 0, 0], [0, 0, -2], 7.0, [0, -30], 0, on_collision="nan")
    assert d[0] > 0 and np.isnan(d[1])
    with pytest.raises(ValueError, match="on_collision"):
        sensor_distance([9, 0, 0], [0, 0, 0], 7.0, 0, 0, on_collision="clip")


def _closest_point_distance(f, centre, radius):
    """Independent path: minimise |f − x| over the sphere surface parametrised by angles."""

    def point(v):
        theta, phi = v
        return centre + radius * np.array(
            [np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)]
        )

    to_f = f - centre
    theta0 = np.arccos(to_f[2] / np.linalg.norm(to_f)) + 0.3
    phi0 = np.arctan2(to_f[1], to_f[0]) - 0.3
    result = minimize(lambda v: np.linalg.norm(f - point(v)), [theta0, phi0], tol=1e-12)
    return result.fun


@settings(max_examples=40, deadline=None)
@given(pitch=st.floats(-30, 30), roll=st.floats(-30, 30))
def test_eq3_matches_numerical_closest_point(pitch, roll):
    f, s0, r = np.array([10.0, 1.0, 0.5]), np.array([0.4, -0.3, -1.8]), 8.0
    centre = rotation_x(roll) @ rotation_y(pitch) @ s0
    expected = _closest_point_distance(f, centre, r)
    assert_allclose(sensor_distance(f, s0, r, pitch, roll), expected, atol=1e-6)


@settings(max_examples=25, deadline=None)
@given(offset=st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3).map(np.array), roll=angles)
def test_zero_offset_gives_pose_independent_distance(offset, roll):
    """A sphere centred on the rotation centre looks the same at every pose."""
    sensor = np.array([10.0, 0.0, 0.0]) + offset
    pitch = np.linspace(-45, 45, 7)
    d = sensor_distance(sensor, [0, 0, 0], 8.0, pitch, roll)
    assert_allclose(d, np.linalg.norm(sensor) - 8.0, atol=1e-12)


def test_surface_normal_points_from_centre_to_sensor():
    n = surface_normal([[10, 0, 0], [0, 10, 0]], [0, 0, -2], 0, 0)
    assert_allclose(n, [[10, 0, 2] / np.sqrt(104), [0, 10, 2] / np.sqrt(104)])


def test_trace_axis_hand_values():
    # sensor at (10, 0, 0) looking along −x at a sphere of radius 8 centred at (0, 0, 3):
    # the axis meets it where x² + 9 = 64, x = sqrt(55); t = 10 − sqrt(55);
    # normal (sqrt(55), 0, −3)/8; incidence acos(sqrt(55)/8)
    hit = trace_axis([10, 0, 0], [-1, 0, 0], [0, 0, 3], 8.0, 0, 0)
    assert_allclose(hit.axial_distance_mm, 10 - np.sqrt(55))
    assert_allclose(hit.point_mm, [np.sqrt(55), 0, 0])
    assert_allclose(hit.normal, [np.sqrt(55) / 8, 0, -3 / 8])
    assert_allclose(hit.incidence_deg, np.rad2deg(np.arccos(np.sqrt(55) / 8)))
    assert_allclose(hit.surface_distance_mm, np.sqrt(109) - 8)
    # the shortest distance never exceeds the distance along the axis
    assert hit.surface_distance_mm < hit.axial_distance_mm


def test_trace_axis_reports_a_miss():
    hit = trace_axis([[10, 0, 0], [10, 0, 0]], [[-1, 0, 0], [1, 0, 0]], [0, 0, 9], 8.0, 0, 0)
    assert np.isnan(hit.axial_distance_mm).all()  # passes above the sphere; looks away
    assert not hit.hit.any()


def test_trace_axis_matches_trimesh_ray_cast():
    """Independent path: cast the posed axes onto a fine triangulated sphere."""
    s0, radius = np.array([0.5, -0.4, -1.5]), 9.0
    sensors = np.array([[10.0, 0.0, 0.3], [0.5, 10.0, -0.2]])
    axes = np.array([[-1.0, 0.05, -0.1], [0.02, -1.0, 0.1]])
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    sphere = trimesh.creation.icosphere(subdivisions=6, radius=radius)
    # icosphere vertices lie on the sphere; flat faces sit inside it by at most the sagitta
    edge = sphere.edges_unique_length.max()
    sagitta = radius - np.sqrt(radius**2 - (edge / np.sqrt(3)) ** 2)
    for pitch, roll in [(0, 0), (15, 0), (-15, 10), (12, -15), (-15, -15)]:
        centre = rotate_centre(s0, pitch, roll)
        mesh = sphere.copy()
        mesh.apply_translation(centre)
        locations, ray_index, _ = mesh.ray.intersects_location(sensors, axes, multiple_hits=False)
        cast = np.linalg.norm(locations - sensors[ray_index], axis=1)
        hit = trace_axis(sensors, axes, s0, radius, pitch, roll)
        assert_allclose(hit.axial_distance_mm[ray_index], cast, atol=2 * sagitta)


def test_sensor_frames_are_orthonormal_and_keep_detector_side():
    frames = sensor_frames([[-2, 0, 0], [0, -1, 0.2]], [[0, 0, 1], [0, 0, 1]])
    for f in frames:
        assert_allclose(f @ f.T, np.eye(3), atol=1e-12)
        assert f[1, 2] > 0  # u leans towards the requested detector direction
    # w = a × u = (−1, 0, 0) × (0, 0, 1) = (0, 1, 0)
    assert_allclose(frames[0], [[-1, 0, 0], [0, 0, 1], [0, 1, 0]])
