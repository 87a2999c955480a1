"""The light path against temperature, by hand and against the circuit of model.electronics."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.model.sensors import NJL5901R_2
from reflector_opt.model.temperature import (
    ThermalCoefficients,
    dark_current_a,
    photocurrent_factor,
    self_heating_k,
    volts_at_temperature,
)
from reflector_opt.util.errors import InputError

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


def test_volts_at_temperature_is_the_circuit_with_changed_gain_and_dark_current():
    """Independent path: the sensor model's own circuit with its gain and dark current set to
    their values at ΔT gives the same output as warming the calibrated output."""
    eta = np.array([1e-3, 5e-3, 2e-2, 4e-2])
    model = NJL5901R_2.with_(dark_current_a=COEFFS.dark_current_a)  # its dark current at 25 °C
    cold = model.output_voltage(eta)
    for dt in (-7.0, 5.0):
        factor = photocurrent_factor(dt, COEFFS, model)
        warm_model = model.with_(
            current_gain=model.current_gain * factor,
            dark_current_a=dark_current_a(dt, COEFFS),
        )
        assert_allclose(
            volts_at_temperature(cold, model, COEFFS, dt),
            warm_model.output_voltage(eta),
            atol=1e-12,
        )
    assert_allclose(volts_at_temperature(cold, model, COEFFS, 0.0), cold, atol=1e-15)


def test_differencing_keeps_the_dark_current():
    cold = NJL5901R_2.output_voltage(np.array([1e-2]))
    no_light = NJL5901R_2.output_voltage(np.array([0.0]))
    warm = volts_at_temperature(no_light, NJL5901R_2, COEFFS, 20.0)
    # 20 K is 2.5 doublings: the dark current grows by (2^2.5 − 1) · 0.1 µA = 0.4657 µA
    assert warm[0] == pytest.approx(3.3 - (2**2.5 - 1) * 1e-7 * 1e4)
    same = volts_at_temperature(no_light, NJL5901R_2, COEFFS, 20.0, dark_current_changes=False)
    assert same[0] == pytest.approx(no_light[0])
    assert volts_at_temperature(cold, NJL5901R_2, COEFFS, 5.0)[0] != cold[0]


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
