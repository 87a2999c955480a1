"""The light-change term of the voltage pipeline, by hand and as the circuit's gain."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.model._operating import OperatingState, apply_state, readings
from reflector_opt.model._sensors import NJL5901R_2, QRE1113


def test_a_light_change_scales_the_photocurrent_by_hand():
    # V = 2.0 V: R2 · I_photo = 1.3 V; 3 % less light raises the output by 0.039 V
    out = apply_state([[2.0, 1.0]], (NJL5901R_2, NJL5901R_2), OperatingState(light_change=-0.03))
    assert_allclose(out, [[2.0 + 0.039, 1.0 + 0.03 * 2.3]], rtol=1e-14)


def test_a_light_change_is_the_circuit_with_a_changed_gain():
    """Independent path: the same coupling through the model with G × (1 + c)."""
    models = (NJL5901R_2, QRE1113)
    eta = np.array([[2e-3, 1e-3], [1e-2, 5e-3]])
    change = np.array([0.02, -0.05])  # one per sensor, as an array on the last axis
    out = readings(eta, models, OperatingState(light_change=change))
    for k, (m, c) in enumerate(zip(models, change, strict=True)):
        assert_allclose(
            out[:, k], m.with_(current_gain=m.current_gain * (1 + c)).output_voltage(eta[:, k])
        )


def test_a_light_change_of_minus_one_or_below_is_refused():
    from reflector_opt.util._errors import InputError

    with pytest.raises(InputError, match="light_change"):
        OperatingState(light_change=-1.0)
