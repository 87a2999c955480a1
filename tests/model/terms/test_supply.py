"""The supply term of the voltage pipeline: by hand, and as the circuit at the new supply."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.model._electronics import collector_current, led_current, output_voltage
from reflector_opt.model._operating import OperatingState, apply_state
from reflector_opt.model._sensors import NJL5901R_2


def moved(volts, model, delta, reference="fixed"):
    state = OperatingState(supply_change_v=delta, adc_reference=reference)
    return apply_state(np.atleast_1d(volts)[:, None], (model,), state)[:, 0]


def test_a_supply_change_by_hand_fixed_and_ratiometric():
    # V = 2.0 V: R2 · I_photo = 3.3 − 2.0 = 1.3 V, headroom Vcc − V_F = 2.1 V, δ = +10 mV
    expected = 2.0 + 0.010 - 1.3 * 0.010 / 2.1
    assert moved(2.0, NJL5901R_2, 0.010)[0] == pytest.approx(expected, rel=1e-14)
    ratiometric = moved(2.0, NJL5901R_2, 0.010, "ratiometric")[0]
    assert ratiometric == pytest.approx(expected * 3.3 / 3.31, rel=1e-14)
    # a saturated output stays saturated; no change, no change
    assert moved(0.2, NJL5901R_2, 0.010)[0] == pytest.approx(0.2)
    assert moved(2.0, NJL5901R_2, 0.0, "ratiometric")[0] == 2.0


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
        assert_allclose(moved(circuit(m.supply_v), m, delta), expected, atol=1e-12)
