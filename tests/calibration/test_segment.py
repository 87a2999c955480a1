"""Segment kinematics, the validation motions and tip errors."""

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

import reflector_opt as ro
from reflector_opt.calibration._segment import (
    PAPER_TABLE_I,
    rotation_angle_deg,
    simulate_segment,
    table_one,
    tip_angles,
    tip_pose,
    unit_rotation,
    validation_motion,
)
from reflector_opt.calibration._simulation import simulate_calibration
from reflector_opt.design import Noise, Workspace
from reflector_opt.util._errors import InputError


def test_unit_rotation_is_rx_roll_times_ry_pitch():
    # Intrinsic X then Y in scipy is the matrix product Rx(a)·Ry(b).
    expected = Rotation.from_euler("XY", [20.0, 35.0], degrees=True).as_matrix()
    assert_allclose(unit_rotation(35.0, 20.0), expected, atol=1e-14)
    # Pitch 90° takes z to +x (right-handed about y).
    assert_allclose(unit_rotation(90.0, 0.0) @ [0, 0, 1], [1, 0, 0], atol=1e-15)


def test_four_units_in_pure_pitch_by_hand():
    rotation, position = tip_pose(np.full(4, 15.0), np.zeros(4), 18.0)
    assert_allclose(tip_angles(rotation), [60.0, 0.0, 0.0], atol=1e-12)
    # p = 18·Σ (sin 15i°, 0, cos 15i°), i = 1…4: each link's end, tilted by the angle so far
    bends = np.deg2rad(15.0 * np.arange(1, 5))
    assert_allclose(position, 18 * np.array([np.sin(bends).sum(), 0.0, np.cos(bends).sum()]))
    # and as the exact values: sin 15° = (√6 − √2)/4, sin 30° = 1/2, sin 45° = √2/2, sin 60° = √3/2
    s15, s75 = (np.sqrt(6) - np.sqrt(2)) / 4, (np.sqrt(6) + np.sqrt(2)) / 4
    x = 18 * (s15 + 0.5 + np.sqrt(2) / 2 + np.sqrt(3) / 2)
    z = 18 * (s75 + np.sqrt(3) / 2 + np.sqrt(2) / 2 + 0.5)
    assert_allclose(position, [x, 0.0, z], rtol=1e-12)


def test_pure_roll_bends_towards_minus_y():
    rotation, position = tip_pose(np.zeros(3), np.full(3, -10.0), 12.0)
    assert_allclose(tip_angles(rotation), [0.0, -30.0, 0.0], atol=1e-12)
    expected_y = 12 * sum(np.sin(np.deg2rad(10 * i)) for i in (1, 2, 3))
    assert_allclose(position[1], expected_y)
    assert_allclose(tip_pose(np.zeros(5), np.zeros(5), 18.0)[1], [0, 0, 90.0])


def test_chain_against_scipy_rotations():
    rng = np.random.default_rng(0)
    pitch, roll = rng.uniform(-15, 15, size=(2, 50, 4))
    rotation, position = tip_pose(pitch, roll, 18.0)
    for k in range(50):
        frame, point = Rotation.identity(), np.zeros(3)
        for i in range(4):
            frame = frame * Rotation.from_euler("XY", [roll[k, i], pitch[k, i]], degrees=True)
            point = point + frame.apply([0, 0, 18.0])
        assert_allclose(rotation[k], frame.as_matrix(), atol=1e-12)
        assert_allclose(position[k], point, atol=1e-11)
        roll_x, pitch_y, twist_z = frame.as_euler("XYZ", degrees=True)
        assert_allclose(tip_angles(rotation[k]), [pitch_y, roll_x, twist_z], atol=1e-9)


def test_rotation_angle_against_scipy_and_for_tiny_angles():
    rng = np.random.default_rng(1)
    a = Rotation.random(20, random_state=rng)
    b = Rotation.random(20, random_state=rng)
    assert_allclose(
        rotation_angle_deg(a.as_matrix(), b.as_matrix()),
        np.rad2deg((a.inv() * b).magnitude()),
        atol=1e-9,
    )
    tiny = Rotation.from_rotvec([1e-9, 0, 0]).as_matrix()
    assert_allclose(rotation_angle_deg(np.eye(3), tiny), np.rad2deg(1e-9), rtol=1e-6)


def test_validation_motion_shares_the_segment_angle():
    pitch, roll = validation_motion("pitch", 4, amplitude_deg=60.0, cycles=4, samples_per_cycle=100)
    assert pitch.shape == roll.shape == (400, 4)
    assert_allclose(roll, 0.0)
    assert_allclose(pitch.max(), 15.0) and assert_allclose(pitch.min(), -15.0)
    assert_allclose(pitch[:, 0], pitch[:, 3])
    pitch, roll = validation_motion("roll", 2, amplitude_deg=20.0, cycles=1, samples_per_cycle=4)
    assert_allclose(roll[:, 0], [0.0, 10.0, 0.0, -10.0], atol=1e-12)
    with pytest.raises(InputError, match="axis"):
        validation_motion("yaw", 4)


class ConstantModel:
    """Estimates every unit at pitch = roll = 0, whatever the voltages."""

    def predict(self, volts):
        return np.zeros((*np.shape(volts)[:-1], 2))


def test_segment_errors_by_hand_with_a_constant_estimate():
    design = ro.default_design()
    errors = simulate_segment(design, ConstantModel(), "pitch", cycles=2, samples_per_cycle=200)
    # Estimated tip: straight, so the tip error is the true tip pitch: 60° sin(2πt).
    summary = errors.summary()
    assert_allclose(summary["rms_deg"], 60 / np.sqrt(2), rtol=1e-12)  # whole cycles
    assert_allclose(summary["max_deg"], 60.0)
    assert_allclose(summary["percent_error"], 100 * (60 / np.sqrt(2)) / 120.0)
    assert_allclose(errors.orientation_error_deg, np.abs(errors.true_angles_deg[:, 0]), atol=1e-9)
    straight = np.array([0, 0, 4 * 18.0])
    _, true_position = tip_pose(
        *validation_motion("pitch", 4, cycles=2, samples_per_cycle=200), 18.0
    )
    assert_allclose(errors.position_error_mm, np.linalg.norm(true_position - straight, axis=-1))


@pytest.fixture(scope="module")
def eq6_model():
    return simulate_calibration(ro.default_design(), "eq6", step_deg=0.5, n_validation=1000).model


def test_unit_errors_accumulate_along_the_segment(eq6_model):
    quiet = ro.default_design().replace(noise=Noise(sigma_v=0.0, adc_bits=32, vref=3.3))
    pitch, roll = validation_motion("pitch", 4, cycles=1, samples_per_cycle=100)
    errors = simulate_segment(quiet, eq6_model, "pitch", cycles=1, samples_per_cycle=100)
    # Each unit sees the same pose, so its Eq 6 misfit repeats: in pure pitch the tip pitch
    # error is 4 × the unit's own pitch error, up to the small cross-coupling of the wrongly
    # estimated rolls (second order).
    volts = ro.voltages(quiet, pitch[:, 0], roll[:, 0])
    unit_error = eq6_model.predict(volts)[:, 0] - pitch[:, 0]
    assert_allclose(errors.axis_error_deg, 4 * unit_error, atol=0.1)
    assert errors.summary()["rms_deg"] > 2 * np.sqrt(np.mean(unit_error**2))


def test_table_one_lists_prediction_and_paper(eq6_model):
    table = table_one(ro.default_design(), eq6_model, cycles=1, samples_per_cycle=100)
    assert set(table) == {"pitch", "roll"}
    for axis in ("pitch", "roll"):
        assert table[axis]["paper"] == PAPER_TABLE_I[axis]
        assert table[axis]["amplitude_deg"] == 60.0
        predicted = table[axis]["predicted"]
        assert 0 < predicted["rms_deg"] <= predicted["max_deg"]
        assert predicted["orientation_max_deg"] >= predicted["max_deg"] - 1e-9


def test_table_one_shrinks_the_motion_to_the_workspace(eq6_model):
    design = ro.default_design()
    narrow = design.replace(workspace=Workspace(pitch_deg=(-10.0, 12.0), roll_deg=(-15.0, 15.0)))
    table = table_one(narrow, eq6_model, cycles=1, samples_per_cycle=20)
    assert table["pitch"]["amplitude_deg"] == 40.0 and table["roll"]["amplitude_deg"] == 60.0
    with pytest.raises(InputError, match="outside the pitch workspace"):
        simulate_segment(narrow, eq6_model, "pitch", amplitude_deg=60.0)
