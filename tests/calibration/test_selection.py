"""Choosing the form and order by cross-validation."""

import numpy as np
import pytest

from reflector_opt.calibration.models import Polynomial
from reflector_opt.calibration.selection import AutoModel
from reflector_opt.util.errors import InputError


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
