"""The electronics: hand values of the circuit and its inverse."""

import numpy as np
from numpy.testing import assert_allclose

from reflector_opt.model._sensors import NJL5901R_2


def test_led_current_and_output_voltage_hand_values():
    m = NJL5901R_2
    assert_allclose(m.led_current_a, (3.3 - 1.2) / 680)  # 3.088 mA through R1 = 680 Ω
    eta = 0.01
    i_c = 2.4 * (2.1 / 680) * 0.01  # G · I_F · η = 74.1 µA
    assert_allclose(m.collector_current(eta), i_c)
    assert_allclose(m.output_voltage(eta), 3.3 - i_c * 10_000)  # R2 = 10 kΩ
    assert_allclose(m.output_voltage(0.0), 3.3)  # dark: the output sits at Vcc
    assert_allclose(m.output_voltage(1.0), 0.2)  # flooded: clamped at V_CE(sat)


def test_more_light_gives_lower_voltage_and_inverse_round_trips():
    m = NJL5901R_2
    eta = np.linspace(0.0, 0.03, 50)
    v = m.output_voltage(eta)
    assert np.all(np.diff(v) < 0)
    assert_allclose(m.coupling_from_voltage(v), eta, atol=1e-15)
