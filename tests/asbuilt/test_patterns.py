"""Plan patterns compared by their Fisher information (asbuilt.patterns), on blocks made here:
a row of one pose is (1, pitch/15°, roll/15°), so M = I + Σ x xᵀ is worked by hand."""

from types import SimpleNamespace

import numpy as np
import pytest

from reflector_opt.asbuilt._patterns import compare_patterns, pattern_row
from reflector_opt.calibration._plans import make_plan
from reflector_opt.design import default_design

WORKSPACE = default_design().workspace  # ±15° in pitch and roll


def _rows(poses_deg):
    poses = np.asarray(poses_deg, dtype=float)
    return np.column_stack([np.ones(len(poses)), poses / 15.0])[:, None, :]  # (n, S = 1, 3)


class _Information(SimpleNamespace):
    """The attributes of a PoseInformation that compare_patterns reads."""

    def at(self, poses_deg):
        return _Information(poses_deg=np.asarray(poses_deg), rows=_rows(poses_deg))


def test_a_row_is_log_det_and_std_ratio_of_its_information():
    rng = np.random.default_rng(4)
    rows = rng.normal(size=(6, 2, 3))
    poses = rng.uniform(-15, 15, size=(6, 2))
    information = np.eye(3) + sum(block.T @ block for block in rows)
    row = pattern_row("sobol", poses, rows)
    assert row.n_poses == 6 and row.log_det == pytest.approx(np.log(np.linalg.det(information)))
    np.testing.assert_allclose(row.ratio, np.sqrt(np.diag(np.linalg.inv(information))))
    np.testing.assert_array_equal(row.poses_deg, poses)  # a pattern keeps its own order
    visited = pattern_row("d-optimal", poses, rows).poses_deg
    assert sorted(map(tuple, visited)) == sorted(map(tuple, poses))
    assert np.all(np.diff(visited[:, 0]) >= 0)  # a rig's order: by rows of pitch
    middle = float(np.sort(row.ratio)[1])
    data = row.to_dict(("a", "b", "c"), target=middle)
    assert len(data["determined"]) == 2
    assert "abc"[int(np.argmax(row.ratio))] not in data["determined"]
    assert data["posterior_prior_ratio"] == dict(zip("abc", row.ratio.tolist(), strict=True))


def test_the_grid_by_hand_and_the_d_optimal_plan_at_least_as_informative():
    # The 3 × 3 grid over ±15°: Σ x xᵀ = diag(9, 6, 6), so M = diag(10, 7, 7).
    candidates = make_plan(WORKSPACE, "grid", 49)
    info = _Information(
        settings={"design": default_design()}, poses_deg=candidates, rows=_rows(candidates)
    )
    grid, optimal = compare_patterns(info, sizes=(9,), patterns=("grid", "d-optimal"))
    np.testing.assert_array_equal(grid.poses_deg, make_plan(WORKSPACE, "grid", 9))
    assert grid.log_det == pytest.approx(np.log(10 * 7 * 7))
    np.testing.assert_allclose(grid.ratio, 1 / np.sqrt([10, 7, 7]))
    assert optimal.pattern == "d-optimal" and optimal.n_poses == 9
    assert optimal.log_det >= grid.log_det - 1e-9
