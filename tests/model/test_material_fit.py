"""A material's ρ and f from a flat-sample curve: recovery from exact curves, refusals."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.model.exact import exact_coupling
from reflector_opt.model.material_fit import fit_material
from reflector_opt.model.sensors import NJL5901R_2 as NJL
from reflector_opt.util.errors import InputError

#: Orders of the exact reference for the synthetic curves: within 0.05 % of its defaults
#: from 0.3 mm on (test_reduced_orders_agree_with_the_defaults), at a fifth of the cost.
ORDERS = {"source_order": 3, "detector_order": (2, 6), "sphere_order": (48, 48)}
FLAT_MM = 1e5  # a sphere this large stands in for the flat sample
DISTANCE = np.geomspace(0.3, 4.0, 10)
NOISE_V = 0.002


def _exact(distance, **orders):
    """Mirror and Lambertian couplings of a flat target from the exact reference."""
    offset = [0.0, 0.0, NJL.emitter_detector_mm]
    parts = [
        exact_coupling([0, 0, 0], [1, 0, 0], offset, [d + FLAT_MM, 0, 0], FLAT_MM, NJL, **orders)
        for d in distance
    ]
    return np.array([p.mirror for p in parts]), np.array([p.lambertian for p in parts])


@pytest.fixture(scope="module")
def basis():
    return _exact(DISTANCE, **ORDERS)


def _curve(basis, reflectance, fraction, seed, noise_v=NOISE_V):
    mirror, lambertian = basis
    eta = reflectance * (fraction * mirror + (1.0 - fraction) * lambertian)
    noise = np.random.default_rng(seed).normal(0.0, noise_v, mirror.size)
    return NJL.output_voltage(eta) + noise


def test_reduced_orders_agree_with_the_defaults():
    d = np.array([0.3, 1.0, 4.0])
    for reduced, default in zip(_exact(d, **ORDERS), _exact(d), strict=True):
        assert_allclose(reduced, default, rtol=1e-3)


@pytest.mark.parametrize(("reflectance", "fraction"), [(0.9, 0.0), (0.8, 0.3), (0.95, 1.0)])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_recovers_reflectance_and_fraction_of_an_exact_curve(basis, reflectance, fraction, seed):
    """Curves from the exact reference (not the fitted model's code), 2 mV of noise."""
    fit = fit_material(DISTANCE, _curve(basis, reflectance, fraction, seed), NJL)
    assert abs(fit.reflectance - reflectance) < 3 * fit.reflectance_sigma
    assert abs(fit.specular_fraction - fraction) < 3 * fit.specular_fraction_sigma
    # 10 readings of 2 mV: ρ to a few thousandths, f to about ±0.01 (the two curves'
    # shapes differ by a few per cent, so f is the weaker number and its error follows ρ's)
    assert 0.001 < fit.reflectance_sigma < 0.006
    assert 0.004 < fit.specular_fraction_sigma < 0.03
    assert -1.0 < fit.correlation < -0.9
    assert 0.001 < fit.rms_residual_v < 0.003
    assert (fit.points, fit.clamped) == (10, 0)
    assert 0.0 <= fit.specular_fraction <= 1.0 and 0.0 < fit.reflectance <= 1.0


def test_standard_errors_match_the_scatter_over_repeated_curves(basis):
    fits = [fit_material(DISTANCE, _curve(basis, 0.8, 0.3, seed), NJL) for seed in range(40)]
    f = np.array([fit.specular_fraction for fit in fits])
    sigma = np.mean([fit.specular_fraction_sigma for fit in fits])
    assert abs(f.mean() - 0.3) < 2 * sigma  # no bias beyond the noise
    assert 0.7 < f.std() / sigma < 1.4


def test_noise_free_curve_is_recovered_and_clamped_readings_are_left_out():
    strong = NJL.with_(current_gain=3.5)  # saturates near the peak of a polished sample
    d = np.linspace(0.3, 4.0, 20)
    volts = strong.output_voltage(strong.flat_coupling(d, 0.95, 0.6))
    fit = fit_material(d, volts, strong)
    assert fit.clamped > 0 and fit.points + fit.clamped == d.size
    assert_allclose([fit.reflectance, fit.specular_fraction], [0.95, 0.6], atol=1e-8)
    assert fit.rms_residual_v < 1e-9
    assert fit.to_dict()["specular_fraction"] == fit.specular_fraction


def test_far_readings_alone_do_not_determine_the_fraction():
    """Far from the sensor both curves fall off alike: f is refused, not guessed."""
    far = np.linspace(2.0, 4.0, 10)
    volts = _curve(_exact(far, **ORDERS), 0.8, 0.3, seed=0)
    with pytest.raises(InputError, match=r"specular fraction is not determined.*near range"):
        fit_material(far, volts, NJL)
    fit = fit_material(far, volts, NJL, max_sigma_f=10.0)  # accepted when asked, and wide
    assert fit.specular_fraction_sigma > 0.3


def test_collinear_curves_are_refused():
    d = np.linspace(1.0, 1.01, 5)  # one distance, in effect
    volts = NJL.output_voltage(NJL.flat_coupling(d, 0.8, 0.3))
    with pytest.raises(InputError, match="same shape"):
        fit_material(d, volts, NJL)


@pytest.mark.parametrize(
    ("distance", "volts", "message"),
    [
        ([0.5, 1.0, 2.0, 3.0], [1.0, np.nan, 2.0, 3.0], "must be finite"),
        ([0.5, -1.0, 2.0, 3.0], [1.0, 1.5, 2.0, 3.0], "must be positive"),
        ([0.5, 1.0, 2.0], [1.0, 1.5, 2.0, 3.0], "equal length"),
        ([0.5, 1.0, 2.0, 3.0, 4.0], [0.2, 0.2, 3.3, 3.3, 3.3], "every reading is clamped"),
        ([0.5, 1.0, 2.0, 3.0, 4.0], [0.2, 0.9, 1.5, 2.0, 3.3], r"at least 4 readings.*found 3"),
        # a constant output was 'f = 0.00 ± 8.7: the curves have nearly the same shape'
        ([0.5, 1.0, 2.0, 3.0, 4.0], [2.0] * 5, "does not change with the distance"),
    ],
)
def test_bad_curves_are_refused(distance, volts, message):
    with pytest.raises(InputError, match=message):
        fit_material(distance, volts, NJL)
