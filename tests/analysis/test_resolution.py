"""Resolution: conditioning and Cramér–Rao bound of hand-built Jacobians, folds, uniqueness."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.spatial.distance import pdist

from reflector_opt.analysis._jacobian import values_and_jacobian, voltage_jacobian
from reflector_opt.analysis._resolution import (
    condition_number,
    crlb_deg,
    fold_fraction,
    jacobian_determinant,
    local_separation_sigma,
    min_separation_sigma,
    resolution_over_poses,
)
from reflector_opt.design import default_design
from reflector_opt.model._forward import voltages

SIGMA = 0.002


# --- hand-built Jacobians -----------------------------------------------------------------------


def test_resolution_over_two_poses_by_hand():
    """Two poses: J = [[0.08, 0.03], [−0.02, 0.06]] and diag(0.1, 0.05) V/deg.

    First pose: JᵀJ = [[0.0068, 0.0012], [0.0012, 0.0045]], det 2.916e-5 (= (det J)² =
    0.0054²), σ_γ = σ·sqrt(0.0045/2.916e-5) = 0.0248452°, σ_α = σ·sqrt(0.0068/2.916e-5) =
    0.0305414°; second: σ/0.1 = 0.02°, σ/0.05 = 0.04°.
    """
    jac = np.array([[[0.08, 0.03], [-0.02, 0.06]], [[0.1, 0.0], [0.0, 0.05]]])
    found = resolution_over_poses(jac, SIGMA)
    first = (0.0248452, 0.0305414)
    assert_allclose(found.worst_deg, [first[0], 0.04], rtol=1e-5)
    assert_allclose(found.worst_deg[1], 0.04)
    rms = np.sqrt([(first[0] ** 2 + 0.02**2) / 2, (first[1] ** 2 + 0.04**2) / 2])
    assert_allclose(found.rms_deg, rms, rtol=1e-5)
    assert found.worst == pytest.approx(0.04)
    singular = resolution_over_poses(np.stack([jac[0], np.zeros((2, 2))]), SIGMA)
    assert singular.worst == math.inf and np.all(np.isinf(singular.rms_deg))


def test_resolution_over_poses_is_the_spread_of_least_squares_over_the_workspace():
    """Independent path: at every pose of a 5° grid of the default design, noisy voltages
    inverted by linear least squares; their RMS error over poses and draws is the bound's
    RMS, and the matrix inverse of JᵀJ gives its worst case."""
    design = default_design()
    pitch, roll = np.meshgrid(np.arange(-15.0, 16.0, 5.0), np.arange(-15.0, 16.0, 5.0))
    jac = voltage_jacobian(design, pitch, roll)
    found = resolution_over_poses(jac, SIGMA)
    cov = SIGMA**2 * np.linalg.inv(np.swapaxes(jac, -1, -2) @ jac)
    assert_allclose(found.worst_deg, np.sqrt(cov[..., [0, 1], [0, 1]]).max(axis=(0, 1)))
    rng = np.random.default_rng(2)
    noise = rng.normal(scale=SIGMA, size=(400, *jac.shape[:-1]))  # (draw, poses..., sensor)
    errors = np.linalg.solve(jac, noise[..., None])[..., 0]  # J square: least squares
    assert_allclose(np.sqrt(np.mean(errors**2, axis=(0, 1, 2))), found.rms_deg, rtol=0.03)


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


@pytest.mark.parametrize("step", [1.0, 0.25])  # 961 and 14641 poses
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


def _all_pairs(volts, poses, sigma_v, separation=1.0):
    """The uniqueness check by brute force: every pair of poses, scipy's distances."""
    apart = pdist(poses) >= separation * (1.0 - 1e-9)
    return pdist(volts / sigma_v)[apart].min() if apart.any() else math.inf


def test_min_separation_equals_all_pairs_on_the_default_design():
    design = default_design()
    pitch, roll = design.workspace.grid(0.5)  # 3721 poses
    volts = voltages(design, pitch, roll)
    p, r = np.broadcast_arrays(pitch, roll)
    poses = np.stack([p.ravel(), r.ravel()], axis=-1)
    expected = _all_pairs(volts.reshape(-1, 2), poses, SIGMA)
    assert min_separation_sigma(volts, pitch, roll, SIGMA) == pytest.approx(expected, rel=1e-12)
    assert expected > 1.0


@pytest.mark.parametrize("outputs", [1, 2, 3])
def test_min_separation_equals_all_pairs_on_scattered_poses(outputs):
    """Poses off any grid, voltages with clusters and repeated values, 1 to 3 outputs."""
    rng = np.random.default_rng(outputs)
    poses = rng.uniform(-15.0, 15.0, (700, 2))
    volts = np.round(rng.normal(size=(700, outputs)) * 0.02, 3)  # ties in every output
    volts[::7] = volts[0]  # a cluster of equal voltages at poses far apart
    expected = _all_pairs(volts, poses, SIGMA, separation=2.0)
    found = min_separation_sigma(volts, poses[:, 0], poses[:, 1], SIGMA, 2.0)
    assert found == pytest.approx(expected, rel=1e-12, abs=0.0)
    volts = rng.normal(size=(700, outputs)) * 0.02  # no two equal
    expected = _all_pairs(volts, poses, SIGMA, separation=2.0)
    found = min_separation_sigma(volts, poses[:, 0], poses[:, 1], SIGMA, 2.0)
    assert found == pytest.approx(expected, rel=1e-12) and expected > 0.0


def test_min_separation_needs_two_poses_far_enough_apart():
    pitch, roll = np.array([[0.0], [0.5]]), np.array([[0.0]])
    assert min_separation_sigma(np.zeros((2, 1, 2)), pitch, roll, SIGMA) == math.inf
