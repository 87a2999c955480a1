"""The pipeline's terms: each state field read by exactly one registered term."""

from dataclasses import fields

import numpy as np
import pytest

from reflector_opt.model import terms
from reflector_opt.model._operating import OperatingState, apply_state
from reflector_opt.model._sensors import NJL5901R_2

#: A value of each field that differs from the state at calibration.
MOVED = {
    "delta_t_k": 5.0,
    "light_change": -0.02,
    "ambient_v": 0.01,
    "crosstalk_v": 0.005,
    "flicker_v": -0.002,
    "supply_change_v": 0.01,
    "settled_share": 0.5,
}


def test_every_state_field_is_read_by_exactly_one_term():
    read = [name for term in terms.TERMS for name in term.FIELDS]
    assert sorted(read) == sorted(f.name for f in fields(OperatingState))
    assert len(read) == len(set(read))


@pytest.mark.parametrize("name", sorted(MOVED))
def test_each_field_moves_the_output_through_the_pipeline(name):
    volts = np.array([[2.0]])
    assert apply_state(volts, (NJL5901R_2,), OperatingState(**{name: MOVED[name]})) != volts


def test_the_state_at_calibration_changes_nothing():
    volts = np.array([[0.4, 1.0], [2.0, 3.1]])
    out = apply_state(volts, (NJL5901R_2, NJL5901R_2), OperatingState())
    np.testing.assert_allclose(out, volts, rtol=1e-15)
