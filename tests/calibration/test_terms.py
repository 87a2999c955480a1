"""Polynomial terms and the change of variable between raw and normalised voltages."""

from fractions import Fraction

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.calibration._models import Eq5, Eq6, Polynomial
from reflector_opt.calibration._terms import (
    input_normalisation,
    is_closed,
    monomials,
    substitute,
    term_name,
    to_raw,
    to_scaled,
)


def test_term_names_and_values():
    assert [term_name(t) for t in [(0, 0), (1, 0), (0, 1), (2, 1), (1, 3)]] == [
        "1",
        "v1",
        "v2",
        "v1^2*v2",
        "v1*v2^3",
    ]
    volts = np.array([[[2.0, 3.0]], [[-1.0, 0.5]]])  # any leading shape
    values = monomials(volts, [(0, 0), (2, 1), (1, 3)])
    assert values.shape == (2, 1, 3)
    assert_allclose(values[:, 0], [[1.0, 12.0, 54.0], [1.0, 0.5, -0.125]])


def test_closed_term_sets():
    assert is_closed(Eq6().terms)
    assert is_closed(Polynomial(5).terms)
    assert is_closed(Eq5(intercept=True).terms)
    assert not is_closed(Eq5().terms)  # no constant: inputs may be scaled, not centred
    assert not is_closed([(0, 0), (2, 0)])


@pytest.mark.parametrize("terms", [Eq6().terms, Polynomial(4).terms])
def test_raw_and_scaled_coefficients_are_the_same_polynomial(terms):
    rng = np.random.default_rng(1)
    coef_scaled = rng.normal(0.0, 10.0, size=(2, len(terms)))
    centre, scale = np.array([2.1, 2.0]), np.array([0.8, 0.7])
    volts = rng.uniform(1.3, 2.9, size=(50, 2))
    raw = to_raw(coef_scaled, terms, centre, scale)
    assert_allclose(
        monomials(volts, terms) @ raw.T,
        monomials((volts - centre) / scale, terms) @ coef_scaled.T,
        atol=1e-9,  # the raw form cancels large terms: round-off ~1e-12 of values ~100
    )
    assert_allclose(to_scaled(raw, terms, centre, scale), coef_scaled, rtol=1e-11)


def test_the_change_of_variable_is_exact_in_rational_arithmetic():
    """to_scaled inverts to_raw exactly: in floats the two differ by round-off alone."""
    terms = Polynomial(4).terms
    rng = np.random.default_rng(2)
    coef = np.array([[Fraction(x) for x in row] for row in rng.normal(0, 50, (2, len(terms)))])
    centre = [Fraction(2.1047), Fraction(2.0963)]
    scale = [Fraction(0.7945), Fraction(0.7958)]
    scaled = substitute(coef, terms, scale, centre)
    back = substitute(
        scaled, terms, [1 / s for s in scale], [-c / s for c, s in zip(centre, scale, strict=True)]
    )
    assert (back == coef).all()


def test_uncentred_terms_convert_without_a_constant():
    terms = Eq5().terms
    coef_scaled = np.array([[1.0, 2.0], [3.0, 4.0]])
    raw = to_raw(coef_scaled, terms, np.zeros(2), np.array([2.0, 4.0]))
    assert_allclose(raw, [[0.5, 0.5], [1.5, 1.0]])


def test_input_normalisation():
    volts = np.array([[1.0, 5.0], [3.0, 5.0], [2.0, 5.0]])
    centre, scale = input_normalisation(volts, centred=True)
    assert_allclose(centre, [2.0, 5.0])
    assert_allclose(scale, [1.0, 1.0])  # the constant v2 gets scale 1, not 0
    centre, scale = input_normalisation(volts, centred=False)
    assert_allclose(centre, [0.0, 0.0])
    assert_allclose(scale, [3.0, 5.0])
