"""Closed-form flat-target couplings: by hand, and against the exact reference."""

import numpy as np
import pytest
from scipy.special import exp1

from reflector_opt.model._exact_model_form import cosine_power_exponent, exact_model_form_coupling
from reflector_opt.model._flat_hankel import flat_couplings, slope_transform, subsurface_ratio
from reflector_opt.model._optics import FLAT_RADIUS_MM, flat_target_coupling
from reflector_opt.model._sensors import NJL5901R_2 as NJL
from reflector_opt.util._errors import InputError

THETA = NJL.divergence_deg
SLOPE = np.tan(np.deg2rad(THETA))
#: A point emitter and a point detector at the same point: the hand closed forms hold.
POINT = NJL.with_(source_radius_mm=1e-7, detector_area_mm2=1e-10, emitter_detector_mm=1e-9)
#: Orders of the exact reference converged to 4·10⁻⁴ on a flat target from 0.3 mm (its
#: spread to 10⁻⁴ from 0.6 mm for ℓ = 0.3 mm; 0.3 mm needs spread orders near 24).
EXACT = {
    "source_order": 5,
    "detector_order": (2, 6),
    "sphere_order": (48, 48),
    "spread_order": (16, 16),
}


def _exact(distance, model, **physics):
    """Mirror and Lambertian couplings of the flat target, exact reference."""
    parts = [
        exact_model_form_coupling(
            np.zeros(3),
            np.array([1.0, 0.0, 0.0]),
            np.array([0.0, 0.0, model.emitter_detector_mm]),
            np.array([d + FLAT_RADIUS_MM, 0.0, 0.0]),
            FLAT_RADIUS_MM,
            model,
            **EXACT,
            **physics,
        )
        for d in distance
    ]
    return np.array([p.mirror for p in parts]), np.array([p.lambertian for p in parts])


def test_slope_transforms_are_one_at_zero_and_gaussian_by_hand():
    for pattern in ("gaussian", "cosine_power", "two_gaussian"):
        assert slope_transform(np.array([0.0, 1e-9]), THETA, pattern) == pytest.approx(1.0)
    # exp(−k² T²/4) at k = 2/T: e⁻¹
    assert slope_transform(2.0 / SLOPE, THETA) == pytest.approx(np.exp(-1.0))
    # the cosine power's Q(u) = u^μ K_μ(u) / (2^(μ−1) Γ(μ)) falls as the Gaussian's near 0:
    # −Q''(0)/4 … the mean-square slope 2/(m − 1), within 1 % of T² (test_exact_model_form)
    u = 1e-2
    m = cosine_power_exponent(THETA)
    assert (1.0 - slope_transform(u, THETA, "cosine_power")) / u**2 == pytest.approx(
        0.25 * 2.0 / (m - 1.0), rel=1e-2
    )


def test_point_source_against_hand_closed_forms():
    """1 mm from a flat target (tests/model/test_exact_model_form.py has the same forms):
    mirror I(0)/(2d)²; Lambertian (m + 1)/((m + 5) π d²) for the cosine power and
    λ(1 − λ e^λ E1(λ))/(π d²), λ = 1/T², for the Gaussian."""
    m = cosine_power_exponent(THETA)
    lam = 1.0 / SLOPE**2
    for pattern, on_axis, lambert in [
        ("cosine_power", (m + 1) / (2 * np.pi), (m + 1) / ((m + 5) * np.pi)),
        ("gaussian", 1 / (np.pi * SLOPE**2), lam * (1 - lam * np.exp(lam) * exp1(lam)) / np.pi),
    ]:
        got = flat_couplings(1.0, POINT, emitter_pattern=pattern)
        area = POINT.detector_area_mm2
        assert got.mirror / area == pytest.approx(on_axis / 4.0, rel=1e-4)
        assert got.lambertian / area == pytest.approx(lambert, rel=1e-4)


@pytest.mark.parametrize(
    ("pattern", "spread_mm", "distance_mm"),
    [
        ("gaussian", 0.0, [0.3, 0.6, 1.5, 4.0]),
        ("cosine_power", 0.1, [0.3, 1.5]),
        ("two_gaussian", 0.3, [0.6, 2.0]),
    ],
)
def test_sensor_against_the_exact_reference(pattern, spread_mm, distance_mm):
    """The NJL5901R-2 (die, detector disc, 0.5 mm offset), near the peak and far from it:
    within 4·10⁻⁴ of the exact reference (whose own error is about that at these orders)."""
    physics = {"emitter_pattern": pattern, "subsurface_mm": spread_mm}
    closed = flat_couplings(distance_mm, NJL, **physics)
    mirror, lambertian = _exact(distance_mm, NJL, **physics)
    np.testing.assert_allclose(closed.mirror, mirror, rtol=4e-4)
    np.testing.assert_allclose(closed.lambertian, lambertian, rtol=4e-4)


def test_gaussian_agrees_with_the_compiled_flat_target():
    d = np.linspace(0.3, 4.0, 12)
    closed = flat_couplings(d, NJL)
    np.testing.assert_allclose(closed.mirror, flat_target_coupling(d, NJL, 1.0, 1.0), rtol=2e-3)
    np.testing.assert_allclose(closed.lambertian, flat_target_coupling(d, NJL, 1.0, 0.0), rtol=2e-3)


def test_spread_ratio_reshapes_the_near_field_and_vanishes_far():
    d = np.array([0.3, 0.5, 1.0, 4.0])
    ratio = subsurface_ratio(d, NJL, 0.1)
    plain = flat_couplings(d, NJL).lambertian
    spread = flat_couplings(d, NJL, subsurface_mm=0.1).lambertian
    np.testing.assert_allclose(ratio, spread / plain)
    # 0.3 mm: the lit spot (1/e radius 0.23 mm) sits inside the 0.5 mm offset, and the
    # spread carries light out to the detector; from 0.5 mm it carries more away from it
    assert ratio[0] > 1.05 and ratio[1] < 0.97
    assert abs(ratio[-1] - 1.0) < 5e-3  # 4 mm: a spot much wider than the spread
    np.testing.assert_array_equal(subsurface_ratio(d, NJL, 0.0), np.ones(4))


def test_bad_options_are_refused():
    with pytest.raises(InputError, match="emitter_pattern"):
        flat_couplings(1.0, NJL, emitter_pattern="lambertian")
    with pytest.raises(InputError, match="subsurface_mm"):
        subsurface_ratio(1.0, NJL, -0.1)
