"""Covariance, determined combinations and profiles, on problems with known answers."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.asbuilt._uncertainty import (
    DETERMINED_RATIO,
    birge_ratio,
    combinations,
    posterior_covariance,
    profile_interval,
)


def _linear_problem(seed=0, n=40, p=3):
    rng = np.random.default_rng(seed)
    return rng.normal(size=(n, p)), np.array([0.5, 2.0, 1.0])


def test_the_posterior_covariance_is_the_spread_of_map_estimates():
    """Monte Carlo of a linear-Gaussian model: the MAP estimates' spread about the truth
    (drawn from the prior) is the Laplace covariance, an independent check of the formula."""
    J, prior = _linear_problem(n=5)  # few data: the prior matters (2× in some variances)
    rng = np.random.default_rng(1)
    errors = []
    for _ in range(4000):
        truth = prior * rng.standard_normal(3)
        y = J @ truth + rng.standard_normal(len(J))
        A = np.vstack([J, np.diag(1 / prior)])
        b = np.r_[y, np.zeros(3)]
        errors.append(np.linalg.lstsq(A, b, rcond=None)[0] - truth)
    empirical = np.cov(np.array(errors).T)
    assert_allclose(posterior_covariance(J, prior, 1.0), empirical, rtol=0.1, atol=2e-3)


def test_a_fixed_parameter_has_zero_covariance_and_the_inflation_widens():
    J, prior = _linear_problem()
    prior[1] = 0.0
    cov = posterior_covariance(J, prior, 1.0)
    assert np.all(cov[1] == 0) and np.all(cov[:, 1] == 0)
    wider = posterior_covariance(J, prior, 4.0)
    assert np.all(np.diag(wider)[[0, 2]] > np.diag(cov)[[0, 2]])


def test_the_birge_ratio_is_the_chi_square_per_degree_of_freedom():
    J, prior = _linear_problem(n=400)
    rng = np.random.default_rng(2)
    assert birge_ratio(rng.standard_normal(400), J, prior) == pytest.approx(1.0, abs=0.2)
    assert birge_ratio(3.0 * rng.standard_normal(400), J, prior) == pytest.approx(9.0, rel=0.2)


def test_only_the_measured_difference_is_named_as_determined():
    """Data that see a − b only (strongly), never a + b or c."""
    J = np.zeros((50, 3))
    J[:, 0], J[:, 1] = 10.0, -10.0
    prior = np.ones(3)
    cov = posterior_covariance(J, prior, 1.0)
    found = combinations(cov, prior, ["a", "b", "c"], str.upper)
    assert len(found) == 1
    assert found[0].name in ("A − B", "B − A")
    assert found[0].ratio == pytest.approx(1 / np.sqrt(1 + 2 * 100 * 50))
    assert set(found[0].weights) == {"a", "b"}
    weak = combinations(posterior_covariance(J * 0.01, prior, 1.0), prior, list("abc"), str)
    assert weak == [] and 1 / np.sqrt(1 + 2 * 0.01 * 50) > DETERMINED_RATIO


def test_a_systematic_term_can_undo_a_determined_combination():
    J = np.zeros((50, 3))
    J[:, 0], J[:, 1] = 10.0, -10.0
    prior = np.ones(3)
    shift = np.array([0.6, -0.6, 0.0])  # a model error along a − b, 0.85 of the prior
    cov = posterior_covariance(J, prior, 1.0) + np.outer(shift, shift)
    assert combinations(cov, prior, list("abc"), str) == []


def test_the_profile_of_a_linear_model_is_the_wald_interval():
    """For linear residuals the 90 % profile interval is estimate ± 1.645 posterior std."""
    J, prior = _linear_problem()
    rng = np.random.default_rng(3)
    y = J @ np.array([0.3, -1.0, 0.5]) + rng.standard_normal(len(J))

    def residuals(x):
        return np.r_[J @ x - y, x / prior]

    A = np.vstack([J, np.diag(1 / prior)])
    x_hat = np.linalg.lstsq(A, np.r_[y, np.zeros(3)], rcond=None)[0]
    std = np.sqrt(np.diag(posterior_covariance(J, prior, 1.0)))
    bounds = (np.full(3, -50.0), np.full(3, 50.0))
    for j in range(3):
        found = profile_interval("p", residuals, x_hat, A, j, std[j], bounds, 1.0, len(J), 10.0)
        assert found.closed
        assert found.low == pytest.approx(10.0 + x_hat[j] - 1.6449 * std[j], rel=1e-3)
        assert found.high == pytest.approx(10.0 + x_hat[j] + 1.6449 * std[j], rel=1e-3)


def test_a_profile_that_meets_the_bound_is_open():
    J = np.ones((5, 1)) * 0.1
    prior = np.array([10.0])

    def residuals(x):
        return np.r_[J @ x, x / prior]

    A = np.vstack([J, np.diag(1 / prior)])
    found = profile_interval(
        "p", residuals, np.zeros(1), A, 0, 5.0, (np.array([0.0]), np.array([100.0])), 1.0, 5, 0
    )
    assert not found.closed and found.low == 0.0
