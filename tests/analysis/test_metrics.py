"""Metrics: Jacobian accuracy, conditioning and Cramér–Rao bound, folds, uniqueness, shell."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

import reflector_opt.analysis.metrics as metrics
from reflector_opt.analysis.metrics import (
    condition_number,
    crlb_deg,
    distance_window,
    evaluate_metrics,
    fold_fraction,
    jacobian_determinant,
    local_separation_sigma,
    min_separation_sigma,
    reflector_reach_mm,
    shell_wall_mm,
    stencil_poses,
    values_and_jacobian,
    voltage_jacobian,
)
from reflector_opt.design import Reflector, default_design
from reflector_opt.model.forward import voltages
from reflector_opt.model.geometry import rotate_centre, rotation_x, rotation_y, sensor_distance

SIGMA = 0.002


# --- hand-built Jacobians -----------------------------------------------------------------------


def test_diagonal_jacobian_gives_known_condition_and_crlb():
    jac = np.array([[0.1, 0.0], [0.0, 0.05]])  # V/deg
    assert condition_number(jac) == pytest.approx(2.0)
    pitch, roll = crlb_deg(jac, SIGMA)
    assert pitch == pytest.approx(SIGMA / 0.1)  # 0.02°
    assert roll == pytest.approx(SIGMA / 0.05)  # 0.04°
    assert jacobian_determinant(jac) == pytest.approx(0.005)


def test_rotated_jacobian_matches_svd_and_matrix_inverse():
    def rot(t):
        return np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])

    jac = rot(0.7) @ np.diag([0.12, 0.03]) @ rot(-0.3).T
    assert condition_number(jac) == pytest.approx(4.0)
    cov = SIGMA**2 * np.linalg.inv(jac.T @ jac)
    pitch, roll = crlb_deg(jac, SIGMA)
    assert_allclose([pitch, roll], np.sqrt(np.diag(cov)), rtol=1e-12)


def test_more_outputs_than_angles_matches_numpy():
    rng = np.random.default_rng(1)
    jac = rng.normal(size=(4, 5, 3, 2)) * 0.05
    assert_allclose(condition_number(jac), np.linalg.cond(jac), rtol=1e-9)
    cov = SIGMA**2 * np.linalg.inv(np.swapaxes(jac, -1, -2) @ jac)
    pitch, roll = crlb_deg(jac, SIGMA)
    assert_allclose(pitch, np.sqrt(cov[..., 0, 0]), rtol=1e-9)
    assert_allclose(roll, np.sqrt(cov[..., 1, 1]), rtol=1e-9)


def test_crlb_is_the_spread_of_the_least_squares_estimate():
    """Monte Carlo: the linear least-squares estimate attains σ_V² (JᵀJ)⁻¹."""
    jac = np.array([[0.08, 0.03], [-0.02, 0.06]])
    rng = np.random.default_rng(7)
    noise = rng.normal(scale=SIGMA, size=(40_000, 2))
    estimates = np.linalg.solve(jac, noise.T).T  # J square: least squares is the inverse
    pitch, roll = crlb_deg(jac, SIGMA)
    assert_allclose(estimates.std(axis=0), [pitch, roll], rtol=0.02)


@pytest.mark.parametrize(
    "jac",
    [
        np.zeros((2, 2)),
        np.array([[1e-200, 0.0], [0.0, 1e-200]]),
        np.array([[0.1, 0.2], [0.05, 0.1]]),
    ],
)
def test_singular_jacobian_is_infinite_without_warnings(jac):
    # pytest turns RuntimeWarning into errors, so a divide-by-zero or overflow would fail here
    assert condition_number(jac) == math.inf
    assert crlb_deg(jac, SIGMA) == (math.inf, math.inf)


# --- the finite-difference Jacobian -----------------------------------------------------------


def test_stencil_layout():
    pitch, roll = stencil_poses(np.array([[1.0], [2.0]]), np.array([[5.0, 6.0, 7.0]]), 0.5)
    assert pitch.shape == roll.shape == (5, 2, 3)
    assert_allclose(pitch[:, 0, 0], [1.0, 1.5, 0.5, 1.0, 1.0])
    assert_allclose(roll[:, 0, 0], [5.0, 5.0, 5.0, 5.5, 4.5])


def _distance_jacobian_analytic(design, pitch, roll):
    """∂d/∂(γ, α) of Eq 3 by the chain rule, per degree (independent of the metrics code)."""
    s0 = np.asarray(design.reflector.centre_mm)
    g, a = np.deg2rad(pitch), np.deg2rad(roll)
    d_ry = np.array([[-np.sin(g), 0, np.cos(g)], [0, 0, 0], [-np.cos(g), 0, -np.sin(g)]])
    d_rx = np.array([[0, 0, 0], [0, -np.sin(a), -np.cos(a)], [0, np.cos(a), -np.sin(a)]])
    rx, ry = rotation_x(roll), rotation_y(pitch)
    s1 = rx @ ry @ s0
    ds_dg = rx @ d_ry @ s0
    ds_da = d_rx @ ry @ s0
    out = []
    for f in design.positions_mm:
        p = f - s1
        u = p / np.linalg.norm(p)
        out.append([-u @ ds_dg, -u @ ds_da])
    return np.array(out) * np.pi / 180.0


@pytest.mark.parametrize("pose", [(0.0, 0.0), (12.0, -7.5), (-15.0, 15.0)])
def test_jacobian_of_eq3_matches_the_analytic_derivative(pose):
    design = default_design()
    reflector = design.reflector

    def distance(p, r):
        return sensor_distance(design.positions_mm, reflector.centre_mm, reflector.radius_mm, p, r)

    _, jac = values_and_jacobian(distance, *pose)
    exact = _distance_jacobian_analytic(design, *pose)
    # mm/deg: the truncation error h²/6·|d'''| is ~1e-9 here; rounding ~1e-13
    assert_allclose(jac, exact, rtol=0, atol=1e-9)
    assert np.abs(exact).max() > 1e-3  # the test is not comparing zeros


def test_voltage_jacobian_agrees_with_richardson_extrapolation():
    design = default_design()
    pitch = np.array([[-15.0], [-3.3], [9.0], [15.0]])
    roll = np.array([[-15.0, 0.0, 7.7, 15.0]])
    jac = voltage_jacobian(design, pitch, roll)
    coarse = voltage_jacobian(design, pitch, roll, step_deg=0.08)
    fine = voltage_jacobian(design, pitch, roll, step_deg=0.04)
    richardson = (4.0 * fine - coarse) / 3.0  # error O(h⁴)
    scale = np.abs(richardson).max()
    assert scale > 1e-3
    assert np.abs(jac - richardson).max() < 1e-5 * scale


# --- folds and uniqueness --------------------------------------------------------------------


def test_fold_fraction():
    assert fold_fraction(np.array([1.0, 2.0, 3.0])) == (1, 0.0)
    assert fold_fraction(np.array([-1.0, -2.0, 3.0, -1.0])) == (-1, 0.25)
    assert fold_fraction(np.array([1.0, 0.0, 3.0, 4.0])) == (1, 0.25)
    assert fold_fraction(np.zeros(5)) == (0, 1.0)


def test_a_folded_map_is_detected_by_det_and_uniqueness():
    """V = k·(γ², α): poses γ and −γ give the same voltages."""
    k = 0.05

    def folded(p, r):
        p, r = np.broadcast_arrays(p, r)
        return k * np.stack([p**2, r], axis=-1)

    pitch, roll = np.linspace(-15, 15, 31)[:, None], np.linspace(-15, 15, 31)[None, :]
    volts, jac = values_and_jacobian(folded, pitch, roll)
    _, fraction = fold_fraction(jacobian_determinant(jac))
    assert 0.4 < fraction < 0.6
    assert min_separation_sigma(volts, pitch, roll, SIGMA) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("step", [1.0, 0.25])  # brute force (961 poses) and k-d trees (14641)
def test_min_separation_of_a_linear_map(step):
    """V = k·A·(γ, α): the separation of two poses depends only on their offset Δ, so the
    answer is min k·|A·Δ|/σ over grid offsets with |Δ| ≥ 1°, found here by enumeration."""
    k = 0.03  # V/deg
    a = np.array([[1.0, 0.2], [0.0, 1.0]])
    n = round(30 / step) + 1
    pitch, roll = np.linspace(-15, 15, n)[:, None], np.linspace(-15, 15, n)[None, :]
    p, r = np.broadcast_arrays(pitch, roll)
    volts = k * np.einsum("ij,...j->...i", a, np.stack([p, r], axis=-1))
    i = np.arange(-12, 13) * step
    offsets = np.stack(np.meshgrid(i, i), axis=-1).reshape(-1, 2)
    offsets = offsets[np.hypot(*offsets.T) >= 1.0 - 1e-12]
    expected = k * np.linalg.norm(offsets @ a.T, axis=-1).min() / SIGMA
    assert min_separation_sigma(volts, pitch, roll, SIGMA) == pytest.approx(expected, rel=1e-9)
    assert expected > 10.0


def test_local_separation_of_a_linear_map():
    k = 0.03
    a = np.array([[1.0, 0.2], [0.0, 1.0]])
    jac = np.broadcast_to(k * a, (4, 5, 2, 2))
    expected = k * np.linalg.svd(a, compute_uv=False).min() / SIGMA
    assert local_separation_sigma(jac, SIGMA) == pytest.approx(expected)
    assert local_separation_sigma(np.zeros((3, 2, 2)), SIGMA) == 0.0


def test_coarse_grids_estimate_separation_at_1_degree():
    design = default_design()
    coarse = evaluate_metrics(design, 3.0).min_separation_sigma
    fine = evaluate_metrics(design, 1.0).min_separation_sigma  # pairs exactly 1° apart
    assert coarse == pytest.approx(fine, rel=0.1)


def test_min_separation_paths_agree(monkeypatch):
    design = default_design()
    pitch, roll = design.workspace.grid(1.0)
    volts = voltages(design, pitch, roll)
    brute = min_separation_sigma(volts, pitch, roll, SIGMA)
    monkeypatch.setattr(metrics, "BRUTE_FORCE_MAX_POSES", 0)
    tree = min_separation_sigma(volts, pitch, roll, SIGMA)
    assert tree == pytest.approx(brute, rel=1e-12)
    assert brute > 1.0


def test_min_separation_needs_two_poses_far_enough_apart():
    pitch, roll = np.array([[0.0], [0.5]]), np.array([[0.0]])
    assert min_separation_sigma(np.zeros((2, 1, 2)), pitch, roll, SIGMA) == math.inf


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


def test_evaluate_metrics_of_the_default_design():
    design = default_design()
    m = evaluate_metrics(design, 1.0)
    pitch, roll = design.workspace.grid(1.0)
    d = sensor_distance(design.positions_mm, (0, 0, -1.5), 9.0, pitch, roll)
    assert_allclose(m.distance_min_mm, d.min(axis=(0, 1)))
    assert_allclose(m.distance_max_mm, d.max(axis=(0, 1)))
    assert m.sensitive and m.fold_fraction == 0.0 and m.det_sign in (-1, 1)
    assert 0.01 < m.worst_pitch_deg < 1.0 and 0.01 < m.worst_roll_deg < 1.0
    # by the 90° symmetry of the layout pitch and roll resolution are nearly equal
    assert m.worst_pitch_deg == pytest.approx(m.worst_roll_deg, rel=0.05)
    assert m.axis_miss_fraction == 0.0
    s1 = rotate_centre((0, 0, -1.5), pitch, roll)
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
