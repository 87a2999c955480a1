"""Candidate poses and their information: the module's Jacobian against this test's own
finite differences of the full model, and the order a rig visits a plan in."""

from dataclasses import replace

import numpy as np
import pytest

from reflector_opt.asbuilt._doe import d_optimal
from reflector_opt.asbuilt._parameters import ParameterLayout
from reflector_opt.asbuilt._poses import candidate_poses, pose_information, visiting_order
from reflector_opt.calibration._plans import make_plan
from reflector_opt.model._forward import voltages
from reflector_opt.tolerance._builtunit import REFERENCE_SIGMA_DEG
from reflector_opt.util._errors import InputError


def _independent_log_det(design, poses):
    """log det(I + AᵀA) from the full model's voltages by this test's own differences.

    A = ∂V/∂x · σ_prior / σ_eff with σ_eff² = σ_V² + σ_ref² |∂V/∂(γ, α)|²; the parameter
    vector's meaning is the layout's (one unit), the derivatives are not.
    """
    layout = ParameterLayout(design, 1)
    working = design.replace(workspace=replace(design.workspace, step_deg=5.0))
    pitch, roll = poses[:, 0], poses[:, 1]

    def volts(x):
        built, mismatch = layout.unit_design(x, 0, working)
        return mismatch.apply(voltages(built, pitch, roll))

    h_deg = 1e-3
    slope_pitch = voltages(design, pitch + h_deg, roll) - voltages(design, pitch - h_deg, roll)
    slope_roll = voltages(design, pitch, roll + h_deg) - voltages(design, pitch, roll - h_deg)
    slope2 = (slope_pitch**2 + slope_roll**2) / (2 * h_deg) ** 2
    sigma = np.sqrt(design.noise.total_sigma_v**2 + REFERENCE_SIGMA_DEG**2 * slope2)
    prior = layout.prior_std()
    columns = []
    for j in range(layout.size):
        step = np.zeros(layout.size)
        step[j] = 1e-3 * prior[j]  # a thousandth of the prior std
        derivative = (volts(step) - volts(-step)) / (2 * step[j])
        columns.append((derivative / sigma).ravel() * prior[j])
    a = np.column_stack(columns)
    return np.linalg.slogdet(np.eye(layout.size) + a.T @ a)[1]


@pytest.mark.parametrize("n_poses", [25, 50])
def test_d_optimal_beats_sobol_and_grid_by_an_independent_jacobian(design, n_poses):
    info = pose_information(design, candidate_poses(design.workspace))
    plan = info.poses_deg[d_optimal(info.rows, n_poses)]
    scores = {
        "d-optimal": _independent_log_det(design, plan),
        "sobol": _independent_log_det(design, make_plan(design.workspace, "sobol", n_poses)),
        "grid": _independent_log_det(design, make_plan(design.workspace, "grid", n_poses)),
    }
    # the module's information agrees with the independent one
    assert info.at(plan).log_det() == pytest.approx(scores["d-optimal"], rel=1e-4)
    assert scores["d-optimal"] > scores["sobol"] + 1.0
    assert scores["d-optimal"] > scores["grid"] + 1.0


def test_visiting_order_is_a_serpentine_over_pitch_rows():
    poses = np.array([[1.0, 5.0], [0.0, 2.0], [1.0, -3.0], [0.0, -1.0], [2.0, 0.0]])
    order = visiting_order(poses)
    np.testing.assert_array_equal(poses[order], [[0, -1], [0, 2], [1, 5], [1, -3], [2, 0]])


def test_candidate_grid_covers_the_workspace_both_ends_included(design):
    poses = candidate_poses(design.workspace, 3.0)
    assert len(poses) == 11 * 11  # ±15° in 3° steps
    assert poses.min(axis=0).tolist() == [-15.0, -15.0]
    assert poses.max(axis=0).tolist() == [15.0, 15.0]
    with pytest.raises(InputError, match="more than 4,000"):
        candidate_poses(design.workspace, 0.3)


@pytest.mark.parametrize("poses", [np.zeros((0, 2)), np.zeros((3, 3)), [[0.0, np.nan]]])
def test_pose_information_refuses_poses_that_are_not_finite_pairs(design, poses):
    with pytest.raises(InputError, match="poses"):
        pose_information(design, poses)
