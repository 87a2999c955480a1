"""Pooling a batch: the batch mean, its uncertainty and the scatter, on synthetic batches.

Each synthetic unit is identified exactly as a linear-Gaussian model would be: its deviation
θ_u = μ + τ·η_u is measured through a fixed rank-deficient Jacobian with unit noise, and its
posterior under the prior N(0, I) (whitened) is what an identification would report.
"""

import numpy as np
import pytest

from reflector_opt.asbuilt.batch import Batch, geometry_names
from reflector_opt.asbuilt.correction import plan_correction
from reflector_opt.asbuilt.pooling import MIN_UNITS, direction_name, pool
from reflector_opt.design import default_design

G = len(geometry_names(2))
#: What the calibration sees: 8 combinations, from well (gain 5) to barely (0.5).
JACOBIAN = np.random.default_rng(99).standard_normal((8, G)) * np.linspace(5, 0.5, 8)[:, None]
PRIOR_STD = np.linspace(0.02, 1.0, G)


def synthetic_batch(n, mu, tau=1.0, seed=0):
    """A Batch of n units whose whitened deviations scatter by τ about μ."""
    rng = np.random.default_rng(seed)
    information = JACOBIAN.T @ JACOBIAN
    posterior = np.linalg.inv(information + np.eye(G))
    deviations, covariances = [], []
    for _ in range(n):
        theta = mu + tau * rng.standard_normal(G)
        data = JACOBIAN @ theta + rng.standard_normal(len(JACOBIAN))
        deviations.append(posterior @ JACOBIAN.T @ data * PRIOR_STD)
        covariances.append(posterior * np.outer(PRIOR_STD, PRIOR_STD))
    labels = tuple(str(u + 1) for u in range(n))
    return Batch(
        default_design(),
        geometry_names(2),
        PRIOR_STD,
        labels,
        np.array(deviations),
        np.array(covariances),
        np.zeros((n, 1)),
        np.zeros((n, 2)),
        (),
        None,
    )


MU = np.zeros(G)
MU[[0, 3, 4]] = [3.0, -2.0, 1.5]


def test_the_batch_mean_is_within_its_uncertainty_and_calibrated():
    errors, taus = [], []
    for seed in range(60):
        mean = pool(synthetic_batch(6, MU, seed=seed))
        taus.append(mean.scatter_factor)
        errors += [(d.estimate - d.weights @ MU) / d.std for d in mean.directions]
    errors = np.array(errors)
    assert len(errors) == 60 * len(JACOBIAN)
    assert np.sqrt(np.mean(errors**2)) == pytest.approx(1.0, abs=0.1)
    assert np.mean(taus) == pytest.approx(1.0, abs=0.1)


def test_the_scatter_is_estimated_whatever_its_size():
    for tau in (0.3, 2.0):
        found = [pool(synthetic_batch(8, MU, tau, seed=s)).scatter_factor for s in range(20)]
        assert np.median(found) == pytest.approx(tau, rel=0.2)


def test_without_a_systematic_part_the_correction_rarely_changes_anything():
    changed = [plan_correction(pool(synthetic_batch(5, np.zeros(G), seed=s))).changes_anything
               for s in range(100)]  # fmt: skip
    assert sum(changed) <= 12  # 95 % confidence: about 5 expected


def test_a_systematic_part_is_found_and_undone():
    mean = pool(synthetic_batch(6, MU, seed=3))
    correction = plan_correction(mean)
    assert correction.significant and correction.changes_anything
    truth = MU * PRIOR_STD
    residual = truth + correction.change  # what the next print keeps of the systematic part
    applied = [d for d, a in zip(mean.directions, correction.applied, strict=True) if a]
    before = np.array([d.weights @ (truth / PRIOR_STD) for d in applied])
    after = np.array([d.weights @ (residual / PRIOR_STD) for d in applied])
    assert np.all(np.abs(after) <= 3 * np.array([d.std for d in applied]))
    assert np.linalg.norm(after) < 0.5 * np.linalg.norm(before)


def test_fewer_units_are_taken_as_systematic_only_when_asked():
    batch = synthetic_batch(MIN_UNITS - 1, MU, seed=1)
    assumed = pool(batch, assume_systematic=True)
    assert not assumed.separable and assumed.assume_systematic
    assert assumed.scatter_factor == 0.0 and not assumed.scatter_estimated
    cautious = pool(batch)
    assert cautious.scatter_factor == 1.0 and not cautious.assume_systematic
    # without scatter the mean is known as well as the identifications know the units
    assert max(d.std for d in assumed.directions) < min(d.std for d in cautious.directions)


def test_what_the_data_cannot_see_is_named_and_left():
    mean = pool(synthetic_batch(6, MU, seed=0))
    assert len(mean.directions) + len(mean.undetermined) == G
    assert all(np.isnan(d.estimate) and d.ratio > 0.5 for d in mean.undetermined)
    names = mean.to_dict()["not_determined"]
    assert all(isinstance(d["name"], str) and d["name"] for d in names)


def test_a_direction_is_named_by_its_main_terms():
    weights = np.zeros(G)
    weights[[3, 4]] = [0.8, -0.6]
    names = geometry_names(2)
    text = direction_name(weights, names, default_design_words)
    assert text == "reflector centre z − sensor 1 standoff"


def default_design_words(name):
    from reflector_opt.asbuilt.parameters import Layout

    return Layout(default_design(), 1).words(name)
