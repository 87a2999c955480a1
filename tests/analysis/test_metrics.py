"""Metrics of a design: distance window, shell wall, reach, and every metric together."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.analysis._metrics import (
    distance_window,
    evaluate_metrics,
    reflector_reach_mm,
    shell_wall_mm,
)
from reflector_opt.design import Reflector, default_design
from reflector_opt.model._geometry import rotate_centre, sensor_distance

# --- distances and the shell ---------------------------------------------------------------


def test_distance_window_and_margin():
    d = np.array([[[0.6, 1.0]], [[1.4, 2.9]]])  # (2, 1, 2 sensors)
    lo, hi, margin = distance_window(d, [(0.5, 3.0), (0.5, 3.0)])
    assert_allclose(lo, [0.6, 1.0])
    assert_allclose(hi, [1.4, 2.9])
    assert_allclose(margin, [0.1, 0.1])


def test_concentric_shell_is_uniform():
    hit = np.array([[9.0, 0.0, 0.0], [0.0, -9.0, 0.0]])
    wall = shell_wall_mm(hit, np.zeros(3), 9.0, 7.5, np.array([0.0, 2.0]))
    assert_allclose(wall, 1.5)


def test_shell_wall_is_the_minimum_over_the_spot():
    """Analytic minimum against sampling the spherical cap under the spot."""
    s1 = np.array([0.4, -0.3, -1.2])
    radius, inner = 9.0, 7.5
    rng = np.random.default_rng(3)
    for _ in range(5):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        footprint = rng.uniform(0.0, 1.5)
        wall = shell_wall_mm(s1 + radius * n, s1, radius, inner, footprint)
        e1 = np.cross(n, [0.3, 0.5, 0.8])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(n, e1)
        t = np.linspace(0.0, footprint / radius, 200)[:, None]
        phi = np.linspace(0.0, 2 * np.pi, 721)[None, :]
        u = np.cos(t)[..., None] * n + np.sin(t)[..., None] * (
            np.cos(phi)[..., None] * e1 + np.sin(phi)[..., None] * e2
        )
        sampled = (np.linalg.norm(s1 + radius * u, axis=-1) - inner).min()
        assert wall <= sampled + 1e-12
        assert wall == pytest.approx(sampled, abs=2e-4)


def test_reflector_reach_of_the_default_design():
    g = a = np.deg2rad(15.0)
    # s0 = (0, 0, −1.5): |s1_xy|² = 1.5² (sin²γ + cos²γ sin²α), largest at a corner
    expected = 9.0 + 1.5 * math.sqrt(np.sin(g) ** 2 + np.cos(g) ** 2 * np.sin(a) ** 2)
    pitch, roll = default_design().workspace.grid(1.0)
    reach = reflector_reach_mm((0.0, 0.0, -1.5), 9.0, pitch, roll)
    assert reach.shape == (31, 31)
    assert reach.max() == pytest.approx(expected)
    assert reach[15, 15] == pytest.approx(9.0)  # zero pose: the centre is on the axis


# --- all metrics of a design -------------------------------------------------------------------


def test_coarse_grids_estimate_separation_at_1_degree():
    design = default_design()
    coarse = evaluate_metrics(design, 3.0).min_separation_sigma
    fine = evaluate_metrics(design, 1.0).min_separation_sigma  # pairs exactly 1° apart
    assert coarse == pytest.approx(fine, rel=0.1)


def test_evaluate_metrics_of_the_default_design():
    design = default_design()
    m = evaluate_metrics(design, 1.0)
    pitch, roll = design.workspace.grid(1.0)
    d = sensor_distance(design.positions_mm, (0, 0, -1.4), 9.0, pitch, roll)
    assert_allclose(m.distance_min_mm, d.min(axis=(0, 1)))
    assert_allclose(m.distance_max_mm, d.max(axis=(0, 1)))
    assert m.sensitive and m.fold_fraction == 0.0 and m.det_sign in (-1, 1)
    assert 0.01 < m.worst_pitch_deg < 1.0 and 0.01 < m.worst_roll_deg < 1.0
    # by the 90° symmetry of the layout pitch and roll resolution are nearly equal
    assert m.worst_pitch_deg == pytest.approx(m.worst_roll_deg, rel=0.05)
    assert m.axis_miss_fraction == 0.0
    s1 = rotate_centre((0, 0, -1.4), pitch, roll)
    assert m.reach_max_mm == pytest.approx(np.hypot(s1[..., 0], s1[..., 1]).max() + 9.0)
    doc = m.to_dict()
    assert doc["resolution_deg"]["pitch_worst"] == pytest.approx(m.worst_pitch_deg)


def test_zero_offset_has_no_sensitivity_and_says_so():
    design = default_design()
    centred = design.replace(reflector=Reflector(radius_mm=9.0, centre_mm=(0.0, 0.0, 0.0)))
    m = evaluate_metrics(centred, 1.0)  # RuntimeWarnings would fail this test
    assert not m.sensitive
    assert m.worst_pitch_deg == m.worst_roll_deg == m.worst_condition == math.inf
    assert m.det_sign == 0 and m.fold_fraction == 1.0
    assert m.min_separation_sigma == 0.0
    assert_allclose(m.distance_min_mm, 1.0)
    doc = m.to_dict()
    assert doc["sensitive"] is False
    assert doc["resolution_deg"]["pitch_worst"] is None
    assert doc["condition_worst"] is None
