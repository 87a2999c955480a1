"""The parts of a design: reflector, sensors, workspace, mechanics, noise."""

import math

import numpy as np

from reflector_opt.design._components import Workspace


def test_workspace_grid_is_the_paper_protocol(design):
    pitch, roll = design.workspace.grid()
    assert pitch.shape == (301, 1) and roll.shape == (1, 301)  # 90,601 poses
    assert pitch[0, 0] == -15 and roll[0, -1] == 15
    assert math.isclose(pitch[1, 0] - pitch[0, 0], 0.1)


def test_workspace_bounds_and_samples_by_hand():
    workspace = Workspace(pitch_deg=(-10.0, 12.0), roll_deg=(-5.0, 15.0))
    lo, hi = workspace.bounds()
    np.testing.assert_array_equal(lo, [-10.0, -5.0])
    np.testing.assert_array_equal(hi, [12.0, 15.0])
    lo, hi = workspace.bounds(1.5)
    np.testing.assert_array_equal(lo, [-11.5, -6.5])
    np.testing.assert_array_equal(hi, [13.5, 16.5])
    poses = workspace.sample(np.random.default_rng(4), 500)
    assert poses.shape == (500, 2)
    assert np.all(poses >= [-10.0, -5.0]) and np.all(poses <= [12.0, 15.0])
    # both axes spread over their own range, not the other's
    assert poses[:, 0].min() < -9.0 and poses[:, 1].max() > 14.0 and poses[:, 1].min() > -5.0


def test_workspace_poses_by_hand_in_raster_order():
    workspace = Workspace(pitch_deg=(-2.0, 2.0), roll_deg=(0.0, 1.0))
    expected = [[p, r] for p in (-2.0, -1.0, 0.0, 1.0, 2.0) for r in (0.0, 1.0)]
    np.testing.assert_array_equal(workspace.poses(1.0), expected)
    # the default step is the workspace's own, and the list is the broadcast grid, flattened
    pitch, roll = workspace.grid()
    flat = np.broadcast_arrays(pitch, roll)
    np.testing.assert_array_equal(workspace.poses(), np.column_stack([a.ravel() for a in flat]))
