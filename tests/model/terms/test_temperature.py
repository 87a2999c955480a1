"""The temperature term of the voltage pipeline: by hand, and against the circuit itself."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.model._operating import OperatingState, apply_state
from reflector_opt.model._sensors import NJL5901R_2
from reflector_opt.model._temperature import dark_current_a, photocurrent_factor
from tests.model.test_temperature import COEFFS


def warmed(volts, model, dt, **state):
    return apply_state(
        np.asarray(volts)[:, None], (model,), OperatingState(delta_t_k=dt, thermal=COEFFS, **state)
    )[:, 0]


def test_the_term_is_the_circuit_with_changed_gain_and_dark_current():
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
        assert_allclose(warmed(cold, model, dt), warm_model.output_voltage(eta), atol=1e-12)
    assert_allclose(warmed(cold, model, 0.0), cold, atol=1e-15)


def test_by_hand_at_one_output():
    # V = 2.0 V, no dark current in the model: R2·I_photo = 1.3 V; at +10 K the photocurrent
    # is × 0.94 · 1.03 · (1 + 0.02/2.1) and the dark current grows by (2^1.25 − 1) · 0.1 µA
    factor = 0.94 * 1.03 * (1.0 + 0.02 / 2.1)
    expected = 3.3 - 1.3 * factor - 1e4 * (2**1.25 - 1.0) * 1e-7
    assert warmed([2.0], NJL5901R_2, 10.0)[0] == pytest.approx(expected, rel=1e-12)


def test_differencing_keeps_the_dark_current():
    cold = NJL5901R_2.output_voltage(np.array([1e-2]))
    no_light = NJL5901R_2.output_voltage(np.array([0.0]))
    # 20 K is 2.5 doublings: the dark current grows by (2^2.5 − 1) · 0.1 µA = 0.4657 µA
    assert warmed(no_light, NJL5901R_2, 20.0)[0] == pytest.approx(3.3 - (2**2.5 - 1) * 1e-3)
    same = warmed(no_light, NJL5901R_2, 20.0, dark_current_changes=False)
    assert same[0] == pytest.approx(no_light[0])
    assert warmed(cold, NJL5901R_2, 5.0)[0] != cold[0]
