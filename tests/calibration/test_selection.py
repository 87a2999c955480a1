"""Choosing the form and order by cross-validation."""

import numpy as np
import pytest

from reflector_opt.calibration._models import Polynomial
from reflector_opt.calibration._selection import AutoModel, polynomial_cv_errors
from reflector_opt.calibration._validation import cross_validate
from reflector_opt.util._errors import FitError, InputError


def _data(degree, n=400, noise_deg=0.01, seed=0):
    """Angles that a polynomial of ``degree`` in the voltages gives exactly, plus noise."""
    rng = np.random.default_rng(seed)
    volts = rng.uniform(0.5, 2.5, (n, 2))
    terms = Polynomial(degree).terms
    coef = rng.normal(0.0, 3.0, (2, len(terms)))
    angles = np.stack([volts[:, 0] ** a * volts[:, 1] ** b for a, b in terms], -1) @ coef.T
    return volts, angles + rng.normal(0.0, noise_deg, angles.shape)


def test_chooses_the_low_order_that_fits():
    volts, angles = _data(2)
    auto = AutoModel().fit(volts, angles)
    assert auto.selected_.name == "poly2"
    error = auto.predict(volts) - angles
    assert np.sqrt(np.mean(error**2)) < 0.012


def test_chooses_a_higher_order_when_the_data_need_it():
    volts, angles = _data(5)
    assert AutoModel().fit(volts, angles).selected_.name in {"poly5", "poly6"}


def test_choice_is_within_one_standard_error_of_the_best():
    volts, angles = _data(4, noise_deg=0.05)
    auto = AutoModel().fit(volts, angles)
    best = min(auto.scores_, key=lambda s: s["mse"])
    chosen = next(s for s in auto.scores_ if s["model"] == auto.selected_.name)
    assert chosen["mse"] <= best["mse"] + best["mse_se"]
    simpler = [s for s in auto.scores_ if s["n_terms"] < chosen["n_terms"]]
    assert all(s["mse"] > best["mse"] + best["mse_se"] for s in simpler)


def test_few_samples_leave_out_large_forms_and_none_is_refused():
    volts, angles = _data(1, n=20)
    auto = AutoModel().fit(volts, angles)
    assert max(s["n_terms"] for s in auto.scores_) <= 8  # 16 training samples, 2 per term
    with pytest.raises(InputError, match="too few"):
        AutoModel().fit(volts[:3], angles[:3])
    with pytest.raises(InputError, match="not fitted"):
        AutoModel().predict(volts)


@pytest.mark.parametrize("n, folds, seed", [(60, 5, 0), (400, 5, 3), (1000, 3, 7), (97, 10, 1)])
def test_nested_cross_validation_equals_fitting_each_degree_alone(n, folds, seed):
    """One QR per fold gives every degree's held-out errors as separate fits do."""
    volts, angles = _data(5, n=n, noise_deg=0.05, seed=seed)
    training = n * (folds - 1) // folds
    degrees = [d for d in range(1, 9) if training >= 2 * len(Polynomial(d).terms)]
    nested = polynomial_cv_errors(volts, angles, degrees, folds, seed)
    assert sorted(nested) == degrees
    for d in degrees:
        alone = cross_validate(Polynomial(d), volts, angles, folds, seed)["errors_deg"]
        np.testing.assert_allclose(nested[d], alone, rtol=0, atol=1e-9 * np.abs(alone).max())


def test_a_rank_deficient_degree_is_left_to_the_ordinary_path():
    volts, angles = _data(2, n=200)
    volts[:, 1] = 2.0 * volts[:, 0] + 0.1  # one signal: every degree above 0 is degenerate
    assert polynomial_cv_errors(volts, angles, [1, 2], 5, 0) == {}
    with pytest.raises(FitError, match="rank"):
        AutoModel(candidates=("poly1",)).fit(volts, angles)
