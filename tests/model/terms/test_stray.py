"""The stray-light term of the voltage pipeline: ambient light and crosstalk."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.model._operating import OperatingState, apply_state
from reflector_opt.model._sensors import NJL5901R_2
from reflector_opt.util._errors import InputError

MODELS = (NJL5901R_2, NJL5901R_2)
VOLTS = np.array([[1.0, 2.0], [2.5, 0.5]])


def test_ambient_light_lowers_each_output_by_its_drop():
    out = apply_state(VOLTS, MODELS, OperatingState(ambient_v=(0.01, 0.0)))
    assert_allclose(out, VOLTS - [[0.01, 0.0]], atol=1e-12)


def test_crosstalk_is_signed_and_per_pose():
    drop = np.array([[0.004, -0.002], [-0.001, 0.0]])  # a neighbour's light up or down
    out = apply_state(VOLTS, MODELS, OperatingState(crosstalk_v=drop))
    assert_allclose(out, VOLTS - drop, atol=1e-12)


def test_output_never_falls_below_saturation():
    out = apply_state(VOLTS, MODELS, OperatingState(ambient_v=1.0))
    assert out.min() == pytest.approx(NJL5901R_2.saturation_v)


def test_negative_ambient_light_is_refused():
    with pytest.raises(InputError, match="ambient_v"):
        OperatingState(ambient_v=-0.01)
