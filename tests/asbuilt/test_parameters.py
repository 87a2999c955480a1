"""The as-built parameter layout: priors, the unit a vector describes, and its inverse."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.asbuilt._parameters import (
    REFERENCE_STD_FLOOR_DEG,
    ParameterLayout,
    reference_std_of,
    sensor_frame,
    true_deviations,
    true_pose,
)
from reflector_opt.tolerance._tolerances import Spread, Tolerances, as_built, draw_sample


def test_the_sensor_frame_of_the_default_design(design):
    # S1 at (10, 0, 0) looks along -x, its detector towards +z: c = a × e = (-1,0,0) × (0,0,1)
    a, e, c = sensor_frame(design.sensors[0])
    assert_allclose(a, [-1, 0, 0])
    assert_allclose(e, [0, 0, 1])
    assert_allclose(c, [0, 1, 0])


def test_a_standoff_moves_the_sensor_away_from_the_reflector(design):
    layout = ParameterLayout(design, 1)
    x = np.zeros(layout.size)
    names = layout.names()
    x[names.index("unit 1: sensor_1_standoff_mm")] = 0.1
    x[names.index("unit 1: sensor_1_tilt_led_detector_deg")] = 45.0
    x[names.index("unit 1: reflector_radius_mm")] = -0.2
    built, mismatch = layout.unit_design(x, 0)
    assert_allclose(built.sensors[0].position_mm, [10.1, 0.0, 0.0])
    # tipped by 45° towards its detector (+z): the axis is (-1, 0, 1)
    assert_allclose(built.sensors[0].axis, [-1.0, 0.0, 1.0], atol=1e-12)
    assert built.reflector.radius_mm == pytest.approx(design.reflector.radius_mm - 0.2)
    assert mismatch.gain == (1.0, 1.0)


def test_priors_come_from_the_tolerances_uniform_as_half_width_over_root_three(design):
    tolerances = Tolerances(gain=Spread(0.03, "uniform"))
    layout = ParameterLayout(design, 2, tolerances)
    prior = dict(zip(layout.names(), layout.prior_std(), strict=True))
    assert prior["unit 2: sensor_1_gain"] == pytest.approx(0.03 / math.sqrt(3))
    assert prior["unit 1: reflector_centre_z_mm"] == 0.025
    assert prior["unit 1: sensor_2_tilt_sideways_deg"] == 1.0
    assert prior["specular_fraction"] == 0.05
    assert prior["unit 1: sensor_1_divergence_deg"] == 2.0
    assert prior["unit 2: sensor_2_source_radius_mm"] == 0.03
    assert len(prior) == layout.size == 2 + 2 * (4 + 2 * 9)


@pytest.mark.parametrize("index", range(6))
def test_true_deviations_invert_the_layout_for_tolerance_model_units(design, index):
    """A unit drawn by the tolerance model (its own parametrisation of positions and tilts)
    is rebuilt exactly from the block true_deviations gives."""
    tolerances = Tolerances(sensor_tilt_deg=Spread(3.0))
    built, electrical = as_built(design, tolerances, draw_sample(tolerances, 2, 7, index))
    layout = ParameterLayout(design, 1, tolerances)
    x = np.zeros(layout.size)
    x[layout.unit_slice(0)] = true_deviations(design, built, electrical.mismatch)
    rebuilt, mismatch = layout.unit_design(x, 0)
    assert_allclose(rebuilt.reflector.radius_mm, built.reflector.radius_mm, rtol=1e-13)
    assert_allclose(rebuilt.reflector.centre_mm, built.reflector.centre_mm, atol=1e-13)
    for mine, theirs in zip(rebuilt.sensors, built.sensors, strict=True):
        assert_allclose(mine.position_mm, theirs.position_mm, atol=1e-12)
        axis = np.asarray(theirs.axis) / np.linalg.norm(theirs.axis)
        assert_allclose(np.asarray(mine.axis) / np.linalg.norm(mine.axis), axis, atol=1e-12)
    assert_allclose(mismatch.gain, electrical.mismatch.gain, rtol=1e-14)
    assert_allclose(mismatch.offset_v, electrical.mismatch.offset_v, atol=1e-15)


def test_bounds_keep_the_surface_physical(design):
    layout = ParameterLayout(design, 1)
    lower, upper = layout.bounds()
    nominal = layout.nominal()
    assert nominal[1] + lower[1] == pytest.approx(0.0)  # f ≥ 0
    assert nominal[0] + upper[0] <= 1.0  # ρ ≤ 1
    assert upper[2] == pytest.approx(6 * 0.025)


def test_words_name_the_parameters(design):
    layout = ParameterLayout(design, 1)
    assert layout.words("unit 1: sensor_2_standoff_mm") == "sensor 2 standoff"
    assert layout.words("reflectance") == "surface reflectance"
    assert layout.words("unit 3: reflector_radius_mm") == "reflector radius"


# --- the angle reference ----------------------------------------------------------------------


def test_true_pose_undoes_the_reading_by_hand():
    # a reference twisted by 90° reads (γ, α)·[[0, 1], [−1, 0]] = (−α, γ); zero (1, −2)
    assert_allclose(true_pose(-5.0 + 1.0, 3.0 - 2.0, (1.0, -2.0, 90.0)), (3.0, 5.0), atol=1e-12)
    # no twist: only the zero is taken off
    assert_allclose(true_pose([2.5, 0.0], [-1.0, 4.0], (0.5, 1.0, 0.0)), ([2.0, -0.5], [-2.0, 3.0]))


def test_true_pose_inverts_the_error_budgets_reading():
    """The convention of reflector_opt.analysis._budget's reference term: read = true·R + z."""
    from reflector_opt.analysis import _budget as budget
    from reflector_opt.design._conditions import Conditions

    class Grid:  # the two attributes budget._reference reads
        pitch_deg = np.array([-12.0, 3.0, 14.0])
        roll_deg = np.array([7.0, -9.0, 0.5])

    conditions = Conditions(reference_zero_deg=[0.7, -1.2], reference_twist_deg=0.8)
    errors = budget._reference(Grid, conditions)  # the sign scenarios; the first is (+, +, +)
    truth = np.stack([Grid.pitch_deg, Grid.roll_deg], axis=-1)
    read = truth + errors[0]
    back = true_pose(read[:, 0], read[:, 1], (0.7, -1.2, 0.8))
    assert_allclose(np.stack(back, axis=-1), truth, atol=1e-12)


def test_a_pitch_zero_offset_is_the_sphere_centre_rotated_about_the_joint(design):
    """Why calibration data cannot tell them apart: at every pose the voltages of a unit read
    δ too much pitch are those of the unit whose sphere centre is Ry(−δ)·s0 (Eq 1)."""
    from dataclasses import replace

    from reflector_opt.model._forward import voltages

    delta = np.deg2rad(2.0)
    centre = np.asarray(design.reflector.centre_mm)
    rotated = np.array(
        [[np.cos(delta), 0, -np.sin(delta)], [0, 1, 0], [np.sin(delta), 0, np.cos(delta)]]
    )
    moved = design.replace(reflector=replace(design.reflector, centre_mm=tuple(rotated @ centre)))
    pitch, roll = np.array([-10.0, 0.0, 4.0, 12.0]), np.array([3.0, -8.0, 0.0, 11.0])
    assert_allclose(voltages(moved, pitch + 2.0, roll), voltages(design, pitch, roll), atol=1e-9)
    # on the default design, s0 = (0, 0, −1.4): 2° is 49 µm of centre along x
    assert (rotated @ centre)[0] == pytest.approx(1.4 * np.sin(delta))


def test_a_layout_with_the_reference_carries_three_parameters_per_unit(design):
    std = {
        "reference_pitch_zero_deg": 1.5,
        "reference_roll_zero_deg": 0.0,
        "reference_twist_deg": 0.5,
    }
    layout = ParameterLayout(design, 2, reference_std=std)
    assert layout.size == 2 + 2 * (22 + 3)
    prior = dict(zip(layout.names(), layout.prior_std(), strict=True))
    assert prior["unit 2: reference_twist_deg"] == 0.5
    assert prior["unit 1: reference_roll_zero_deg"] == 0.0  # fixed
    assert prior["unit 2: reflector_radius_mm"] == 0.025  # the blocks keep their order
    assert layout.words("unit 1: reference_pitch_zero_deg") == "reference pitch zero"
    x = np.zeros(layout.size)
    x[layout.reference_slice(1)] = (1.0, -2.0, 90.0)
    angles = np.array([[-4.0, 1.0]])
    assert_allclose(layout.true_angles(x, 1, angles), [[3.0, 5.0]], atol=1e-12)
    assert_allclose(layout.true_angles(x, 0, angles), angles)
    assert ParameterLayout(design, 1).reference_names == ()  # without: the reference is exact


def test_the_reference_prior_from_conditions_is_their_magnitudes_floored():
    from reflector_opt.design._conditions import Conditions

    found = reference_std_of(Conditions(reference_zero_deg=[-0.3, 0.0], reference_twist_deg=0.2))
    assert found == {
        "reference_pitch_zero_deg": 0.3,
        "reference_roll_zero_deg": REFERENCE_STD_FLOOR_DEG,
        "reference_twist_deg": 0.2,
    }
