"""The light path against temperature, by hand and against the circuit of model.electronics."""

import pytest

from reflector_opt.model._sensors import NJL5901R_2
from reflector_opt.model._temperature import (
    ThermalCoefficients,
    dark_current_a,
    photocurrent_factor,
    self_heating_k,
)
from reflector_opt.util._errors import InputError

COEFFS = ThermalCoefficients(
    led_output_per_k=-0.006,
    detector_gain_per_k=0.003,
    forward_voltage_v_per_k=-0.002,
    dark_current_a=1e-7,
    dark_doubling_k=8.0,
    thermal_resistance_k_per_w=400.0,
)


def test_photocurrent_factor_by_hand():
    # 10 K: LED 0.94, detector 1.03, drive 1 + 0.02 V / (3.3 − 1.2) V
    expected = 0.94 * 1.03 * (1.0 + 0.02 / 2.1)
    assert photocurrent_factor(10.0, COEFFS, NJL5901R_2) == pytest.approx(expected, rel=1e-12)
    assert photocurrent_factor(0.0, COEFFS, NJL5901R_2) == 1.0


def test_dark_current_doubles_every_doubling_interval():
    assert dark_current_a(8.0, COEFFS) == pytest.approx(2e-7)
    assert dark_current_a(-16.0, COEFFS) == pytest.approx(2.5e-8)


def test_self_heating_by_hand():
    # I_F = (3.3 − 1.2) / 680 = 3.088 mA; 1.2 V · 3.088 mA · 400 K/W = 1.482 K
    rise = 400.0 * 1.2 * 2.1 / 680.0
    assert self_heating_k(NJL5901R_2, COEFFS) == pytest.approx(rise)
    assert self_heating_k(NJL5901R_2, COEFFS, duty=0.25) == pytest.approx(rise / 4)
    with pytest.raises(InputError, match="duty"):
        self_heating_k(NJL5901R_2, COEFFS, duty=2.0)


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("led_output_per_k", 0.5),
        ("detector_gain_per_k", float("nan")),
        ("forward_voltage_v_per_k", -1.8),  # millivolts given as volts
        ("dark_current_a", -1e-9),
        ("dark_doubling_k", 0.0),
        ("thermal_resistance_k_per_w", 1e6),
    ],
)
def test_absurd_coefficients_are_refused_naming_the_key(key, value):
    with pytest.raises(InputError, match=key):
        ThermalCoefficients(**{key: value})


def test_a_published_curve_at_constant_forward_current_replaces_the_split():
    # the VCNT2020's Fig. 8: +0.40 %/K, −2e-6 /K², with TK_VF −1.0 mV/K through R1
    coefficients = ThermalCoefficients(
        output_per_k=0.004, output_per_k2=-2e-6, forward_voltage_v_per_k=-0.001
    )
    dt = 5.0
    expected = (1 + 0.004 * 5 - 2e-6 * 25) * (1 + 0.005 / 2.1)
    assert photocurrent_factor(dt, coefficients, NJL5901R_2) == pytest.approx(expected, rel=1e-12)
    # the split keeps its meaning, with the curvature multiplied on
    split = ThermalCoefficients(
        led_output_per_k=-0.005,
        detector_gain_per_k=0.002,
        forward_voltage_v_per_k=0.0,
        output_per_k2=-4e-5,
    )
    by_hand = 0.975 * 1.01 * (1 - 4e-5 * 25)
    assert photocurrent_factor(dt, split, NJL5901R_2) == pytest.approx(by_hand, rel=1e-12)


@pytest.mark.parametrize(("key", "value"), [("output_per_k", 0.5), ("output_per_k2", 0.01)])
def test_absurd_published_curves_are_refused_naming_the_key(key, value):
    with pytest.raises(InputError, match=key):
        ThermalCoefficients(**{key: value})
