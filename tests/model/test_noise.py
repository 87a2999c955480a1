"""Noise, ADC quantisation and gain/offset mismatch."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.model._noise import Mismatch, add_noise, measure, quantise
from reflector_opt.util._errors import InputError


def test_quantise_hand_values():
    lsb = 3.3 / 4096
    # 1.0 V / LSB = 1241.2 -> code 1241; 0.2 LSB rounds down, 0.6 LSB up; clipped at both rails.
    volts = np.array([1.0, 0.2 * lsb, 0.6 * lsb, -0.5, 3.3, 5.0])
    expected = np.array([1241, 0, 1, 0, 4095, 4095]) * lsb
    assert_allclose(quantise(volts, 12, 3.3), expected, rtol=0, atol=1e-15)


def test_quantisation_error_is_uniform_within_half_an_lsb():
    rng = np.random.default_rng(1)
    volts = rng.uniform(0.5, 2.5, 200_000)
    error = quantise(volts, 10, 3.3) - volts
    lsb = 3.3 / 1024
    assert np.abs(error).max() <= lsb / 2 + 1e-15
    assert_allclose(np.sqrt(np.mean(error**2)), lsb / np.sqrt(12), rtol=0.01)


def test_noise_has_the_requested_rms_and_is_seeded():
    volts = np.full((100_000, 2), 2.0)
    a = add_noise(volts, 0.002, np.random.default_rng(3))
    b = add_noise(volts, 0.002, np.random.default_rng(3))
    assert_allclose(a, b)
    assert_allclose((a - volts).std(axis=0), 0.002, rtol=0.02)
    assert_allclose(add_noise(volts, 0.0, np.random.default_rng(3)), volts)


def test_mismatch_applies_gain_then_offset_per_sensor():
    m = Mismatch(gain=(1.1, 0.9), offset_v=(0.05, -0.02))
    assert_allclose(m.apply([[2.0, 1.0], [1.0, 2.0]]), [[2.25, 0.88], [1.15, 1.78]])


def test_mismatch_draw_statistics():
    rng = np.random.default_rng(0)
    draws = [Mismatch.draw(rng, 2, 0.02, 0.01) for _ in range(4000)]
    gains = np.array([d.gain for d in draws])
    offsets = np.array([d.offset_v for d in draws])
    assert_allclose(gains.mean(axis=0), 1.0, atol=0.002)
    assert_allclose(gains.std(axis=0), 0.02, rtol=0.05)
    assert_allclose(offsets.std(axis=0), 0.01, rtol=0.05)


def test_measure_composes_mismatch_noise_and_adc():
    volts = np.array([[1.0, 2.0]])
    m = Mismatch(gain=(2.0, 1.0), offset_v=(0.0, 0.1))
    out = measure(volts, np.random.default_rng(0), adc_bits=12, vref=3.3, mismatch=m)
    assert_allclose(out, quantise([[2.0, 2.1]], 12, 3.3))


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: quantise([1.0], 0, 3.3), "adc_bits"),
        (lambda: quantise([1.0], 12.5, 3.3), "adc_bits"),
        (lambda: quantise([1.0], 12, 0.0), "vref"),
        (lambda: add_noise([1.0], -0.1, np.random.default_rng()), "sigma_v"),
        (lambda: Mismatch(gain=(1.0,), offset_v=(0.0, 0.0)), "mismatch"),
        (lambda: Mismatch().apply(np.zeros((4, 3))), "3"),
    ],
)
def test_bad_arguments(call, message):
    with pytest.raises(InputError, match=message):
        call()
