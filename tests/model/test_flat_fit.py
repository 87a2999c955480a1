"""The joint fit of flat-target curves: recovery from closed-form curves, bounds, the LED-pattern
refit, refusals."""

import numpy as np
import pytest

from reflector_opt.model._flat_fit import FlatCurve, fit_flat_curves, refit_with_pattern
from reflector_opt.model._flat_hankel import flat_couplings
from reflector_opt.model._sensors import NJL5901R_2 as NJL
from reflector_opt.util._errors import InputError

D = np.round(np.r_[np.arange(0.3, 1.6, 0.1), np.arange(1.6, 4.01, 0.2)], 2)
#: The true sensor: another beam and gain than the preset the fit starts from.
TRUE = NJL.with_(source_radius_mm=0.18, divergence_deg=28.0, current_gain=2.2)


def _volts(reflectance, fraction, spread_mm=0.0, pattern="gaussian", offset_v=0.0):
    """The true sensor's readings by the closed form (not the fit's compiled model)."""
    parts = flat_couplings(D, TRUE, emitter_pattern=pattern, subsurface_mm=spread_mm)
    return TRUE.output_voltage(parts.total(reflectance, fraction)) + offset_v


def _curves(spread_mm=0.1, pattern="gaussian", sample=(0.85, 0.2)):
    return [
        FlatCurve(D, _volts(0.9, 0.0, pattern=pattern, offset_v=-0.05), 0.9, 0.0),
        FlatCurve(D, _volts(*sample, spread_mm, pattern, offset_v=-0.03)),
    ]


def test_recovers_the_sensor_the_offsets_and_the_sample_with_its_spread():
    fit = fit_flat_curves(_curves(), NJL)
    expected = {
        "source_radius_mm": 0.18,
        "divergence_deg": 28.0,
        "current_gain": 2.2,
        "offset_v_0": -0.05,
        "offset_v_1": -0.03,
        "reflectance": 0.85,
        "specular_fraction": 0.2,
        "subsurface_sq_mm2": 0.01,
    }
    assert fit.names == tuple(expected)
    # the closed form and the compiled model agree to 10⁻³ at 0.3 mm, 10⁻⁵ from 0.6 mm; f,
    # from the near field, takes most of that
    tolerance = {
        "source_radius_mm": 2e-3,
        "divergence_deg": 0.05,
        "current_gain": 2e-3,
        "specular_fraction": 3e-3,
    }
    for name, value in expected.items():
        assert fit.value(name) == pytest.approx(value, abs=tolerance.get(name, 1e-3)), name
    assert fit.model.source_radius_mm == pytest.approx(0.18, abs=2e-3)
    assert max(np.max(np.abs(r)) for r in fit.residuals_v) < 5e-4
    # noise-free: the covariance is the σ_V floor's, 2 mV over 25 readings a curve
    assert 0.0 < fit.sigma("reflectance") < 0.02 and 0.0 < fit.sigma("subsurface_sq_mm2") < 3e-3


def test_without_an_offset_the_read_out_offset_bends_the_estimate():
    """A −30 mV offset left out moves f by 0.05 and leaves residuals of tens of mV."""
    curves = _curves(spread_mm=0.0)
    held = dict(fit_sensor=False, subsurface=False)
    with_offset = fit_flat_curves(curves[1:], TRUE, **held)
    without = fit_flat_curves(curves[1:], TRUE, fit_offsets=False, **held)
    assert with_offset.value("reflectance") == pytest.approx(0.85, abs=2e-3)
    assert with_offset.value("specular_fraction") == pytest.approx(0.2, abs=5e-3)
    assert with_offset.value("offset_v_0") == pytest.approx(-0.03, abs=1e-4)
    assert abs(without.value("specular_fraction") - 0.2) > 0.03
    assert np.sqrt(np.mean(without.residuals_v[0] ** 2)) > 0.01
    assert without.names == ("reflectance", "specular_fraction")


def test_every_surface_value_stays_in_its_physical_range():
    """A sample brighter than the reference says (ρ 1.05) is fitted on the bound ρ = 1."""
    fit = fit_flat_curves(_curves(sample=(1.05, 0.1)), NJL)
    assert fit.value("reflectance") == pytest.approx(1.0, abs=1e-9)
    assert 0.0 <= fit.value("specular_fraction") <= 1.0
    assert fit.value("subsurface_sq_mm2") >= 0.0


def test_a_pattern_refit_predicts_the_bias_of_that_led():
    """Curves of a cosine-power LED (closed form), fitted with the Gaussian model: the bias of
    ρ and its prediction by :func:`refit_with_pattern` at the true values, the same in sign
    and within a factor 2 in size."""
    options = dict(fit_sensor=True, subsurface=False)
    fit = fit_flat_curves(_curves(spread_mm=0.0, pattern="cosine_power"), NJL, **options)
    bias = fit.value("reflectance") - 0.85
    truth = fit_flat_curves(_curves(spread_mm=0.0), NJL, **options)  # the Gaussian's own fit
    moved = refit_with_pattern(_curves(spread_mm=0.0), truth, "cosine_power", NJL, **options)
    predicted = moved.value("reflectance") - truth.value("reflectance")
    assert abs(bias) > 2e-3  # the pattern matters
    assert 0.5 < predicted / bias < 2.0


@pytest.mark.parametrize(
    ("curves", "options", "message"),
    [
        ([], {}, "no curve"),
        ([FlatCurve(D, D), FlatCurve(D, D)], {"fit_sensor": False}, "at most one curve"),
        ([FlatCurve(D, D)], {}, "needs a curve of a known target"),
    ],
)
def test_refusals(curves, options, message):
    with pytest.raises(InputError, match=message):
        fit_flat_curves(curves, NJL, **options)
