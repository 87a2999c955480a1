"""The electronics: hand values of the circuit and its inverse."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.model.electronics import (
    collector_current,
    led_current,
    output_voltage,
    supply_changed_readings,
)
from reflector_opt.model.sensors import NJL5901R_2


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


def test_a_supply_change_by_hand_fixed_and_ratiometric():
    # V = 2.0 V: R2 · I_photo = 3.3 − 2.0 = 1.3 V, headroom Vcc − V_F = 2.1 V, δ = +10 mV
    moved = 2.0 + 0.010 - 1.3 * 0.010 / 2.1
    assert supply_changed_readings(2.0, NJL5901R_2, 0.010) == pytest.approx(moved, rel=1e-14)
    ratiometric = supply_changed_readings(2.0, NJL5901R_2, 0.010, "ratiometric")
    assert ratiometric == pytest.approx(moved * 3.3 / 3.31, rel=1e-14)
    # a saturated output stays saturated; no change, no change
    assert supply_changed_readings(0.2, NJL5901R_2, 0.010) == pytest.approx(0.2)
    assert supply_changed_readings(2.0, NJL5901R_2, 0.0, "ratiometric") == 2.0


def test_a_supply_change_is_the_circuit_at_the_new_supply():
    """The same coupling through the circuit's own equations at Vcc and at Vcc + δ."""
    m = NJL5901R_2
    coupling = np.linspace(1e-3, 0.04, 6)  # outputs of 3.2 V down to 0.34 V

    def circuit(vcc):
        current = collector_current(
            coupling,
            current_gain=m.current_gain,
            led_current_a=led_current(vcc, m.led_forward_v, m.led_resistor_ohm),
            dark_current_a=m.dark_current_a,
        )
        return output_voltage(
            current, supply_v=vcc, load_resistor_ohm=m.load_resistor_ohm, saturation_v=0.0
        )

    for delta in (0.05, -0.05):
        expected = circuit(m.supply_v + delta)
        assert_allclose(
            supply_changed_readings(circuit(m.supply_v), m, delta), expected, atol=1e-12
        )
