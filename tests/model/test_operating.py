"""The operating state applied to a unit's voltages."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.model.operating import OperatingState, apply_state
from reflector_opt.model.sensors import NJL5901R_2
from reflector_opt.model.temperature import ThermalCoefficients, volts_at_temperature
from reflector_opt.util.errors import InputError

MODELS = (NJL5901R_2, NJL5901R_2)
VOLTS = np.array([[1.0, 2.0], [2.5, 0.5]])


def test_ambient_light_lowers_each_output_by_its_drop():
    out = apply_state(VOLTS, MODELS, OperatingState(ambient_v=(0.01, 0.0)))
    assert_allclose(out, VOLTS - [[0.01, 0.0]], atol=1e-12)


def test_per_sensor_temperature_and_coefficients():
    a, b = ThermalCoefficients(), ThermalCoefficients(led_output_per_k=-0.008)
    state = OperatingState(delta_t_k=(3.0, -2.0), thermal=(a, b))
    out = apply_state(VOLTS, MODELS, state)
    assert_allclose(out[:, 0], volts_at_temperature(VOLTS[:, 0], NJL5901R_2, a, 3.0))
    assert_allclose(out[:, 1], volts_at_temperature(VOLTS[:, 1], NJL5901R_2, b, -2.0))


def test_output_never_falls_below_saturation():
    out = apply_state(VOLTS, MODELS, OperatingState(ambient_v=1.0))
    assert out.min() == pytest.approx(NJL5901R_2.saturation_v)


@pytest.mark.parametrize(
    ("changes", "key"),
    [
        ({"ambient_v": -0.01}, "ambient_v"),
        ({"delta_t_k": float("nan")}, "delta_t_k"),
        ({"delta_t_k": 298.0}, "delta_t_k"),  # an absolute temperature given as a change
    ],
)
def test_bad_states_are_refused(changes, key):
    with pytest.raises(InputError, match=key):
        OperatingState(**changes)


def test_wrong_number_of_values_is_refused():
    with pytest.raises(InputError, match="delta_t_k"):
        apply_state(VOLTS, MODELS, OperatingState(delta_t_k=(1.0, 2.0, 3.0)))
