"""The voltage pipeline: from coupling and from calibration voltages, per sensor."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.model._electronics import collector_current, output_voltage
from reflector_opt.model._operating import OperatingState, apply_state, photocurrent_v, readings
from reflector_opt.model._sensors import NJL5901R_2, QRE1113
from reflector_opt.model._temperature import ThermalCoefficients
from reflector_opt.util._errors import InputError

MODELS = (NJL5901R_2, QRE1113)


def test_readings_are_the_circuit_of_each_sensor():
    eta = np.array([[0.0, 1e-3], [1e-2, 2e-2], [1.0, 1.0]])
    out = readings(eta, MODELS)
    for k, m in enumerate(MODELS):
        current = collector_current(
            eta[:, k],
            current_gain=m.current_gain,
            led_current_a=m.led_current_a,
            dark_current_a=m.dark_current_a,
        )
        expected = output_voltage(
            current,
            supply_v=m.supply_v,
            load_resistor_ohm=m.load_resistor_ohm,
            saturation_v=m.saturation_v,
        )
        assert_allclose(out[:, k], expected, rtol=1e-14)


def test_from_coupling_and_from_calibration_voltages_agree():
    """Two ends of one pipeline: readings in a state from η, and the voltages at calibration
    taken to that state, are the same where nothing clamps."""
    eta = np.array([[2e-3, 1e-3], [1e-2, 5e-3]])
    state = OperatingState(
        delta_t_k=(3.0, -2.0),
        thermal=(ThermalCoefficients(), ThermalCoefficients(led_output_per_k=-0.008)),
        light_change=-0.01,
        ambient_v=0.002,
        supply_change_v=0.02,
        adc_reference="ratiometric",
    )
    assert_allclose(
        readings(eta, MODELS, state), apply_state(readings(eta, MODELS), MODELS, state), rtol=1e-13
    )


def test_photocurrent_by_hand():
    # Vcc − V − R2 · I_dark with the model's own dark current
    m = NJL5901R_2
    expected = 3.3 - 2.0 - m.load_resistor_ohm * m.dark_current_a
    assert photocurrent_v(np.array([[2.0]]), (m,))[0, 0] == pytest.approx(expected)


@pytest.mark.parametrize(
    ("changes", "key"),
    [
        ({"delta_t_k": float("nan")}, "delta_t_k"),
        ({"delta_t_k": 298.0}, "delta_t_k"),  # an absolute temperature given as a change
        ({"supply_change_v": float("inf")}, "supply_change_v"),
        ({"adc_reference": "battery"}, "adc_reference"),
    ],
)
def test_bad_states_are_refused(changes, key):
    with pytest.raises(InputError, match=key):
        OperatingState(**changes)


def test_wrong_number_of_values_is_refused():
    volts = np.array([[1.0, 2.0]])
    with pytest.raises(InputError, match="delta_t_k"):
        apply_state(volts, MODELS, OperatingState(delta_t_k=(1.0, 2.0, 3.0)))
    with pytest.raises(InputError, match="3 sensor models for 2"):
        apply_state(volts, (*MODELS, NJL5901R_2), OperatingState())
