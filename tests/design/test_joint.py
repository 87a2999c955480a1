"""The joint's law: what of the bearing's clearance the calibration learns and what stays."""

import math

import pytest

from reflector_opt.design import Mechanics
from reflector_opt.design._conditions import Conditions
from reflector_opt.design._joint import FRICTION, clearance_um, joint_shifts


def test_the_default_clearance_is_the_upper_end_of_the_bearing_s_normal_class():
    assert clearance_um(Conditions(), Mechanics()) == 68.0  # GE 6 E, bores up to 12 mm
    assert clearance_um(Conditions(), Mechanics(bearing="GE4E")) == 68.0
    assert clearance_um(Conditions(joint_clearance_um=30.0), Mechanics()) == 30.0


def test_a_free_joint_and_a_reversing_load_keep_half_the_clearance_on_every_axis():
    for conditions in (
        Conditions(joint_clearance_um=30.0, tendon_preload_n=0.0),
        Conditions(joint_clearance_um=30.0, tendon_preload_n=5.0, load_reverses=True),
    ):
        shifts = joint_shifts(conditions, Mechanics())
        assert shifts.stays_um == (15.0, 15.0, 15.0)
        assert shifts.learned_um == 0.0 and not shifts.seated


def test_a_seated_joint_leaves_the_friction_cone_by_hand():
    # μ = 0.2: φ = atan 0.2 = 11.31°, sin φ = 0.19612, 1 − cos φ = 0.019419
    assert FRICTION["kind"] == "assumed" and FRICTION["value"] in FRICTION["range"]
    shifts = joint_shifts(Conditions(joint_clearance_um=68.0, tendon_preload_n=1.0), Mechanics())
    assert shifts.seated and shifts.learned_um == 34.0
    assert shifts.stays_um[0] == pytest.approx(34.0 * 0.196116, rel=1e-5)
    assert shifts.stays_um[1] == shifts.stays_um[0]
    assert shifts.stays_um[2] == pytest.approx(34.0 * 0.0194193, rel=1e-4)
    frictionless = joint_shifts(Conditions(joint_clearance_um=68.0), Mechanics(), friction=0.0)
    assert frictionless.stays_um == (0.0, 0.0, 0.0)
    assert math.isclose(shifts.to_dict()["stays_um"][0], shifts.stays_um[0])
