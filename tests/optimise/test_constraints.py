"""The optimiser's constraints: margins by hand, the worst case over poses, per-pose margins."""

import math

import numpy as np
import pytest

from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.model._geometry import sensor_distance
from reflector_opt.optimiser import Problem
from reflector_opt.optimiser._constraints import (
    ROUNDING,
    Constraint,
    pose_margins,
    worst_case_constraints,
)


def test_margin_and_sense_by_hand():
    upper = Constraint("reach", 2.0, 3.0, True, "mm", 1.0)
    lower = Constraint("wall", 2.0, 3.0, False, "mm", 1.0, detail="dome")
    assert upper.margin == 1.0 and upper.met
    assert lower.margin == -1.0 and not lower.met
    assert upper.to_dict() == {
        "value": 2.0,
        "limit": 3.0,
        "sense": "<=",
        "margin": 1.0,
        "unit": "mm",
        "met": True,
    }
    assert lower.to_dict()["sense"] == ">=" and lower.to_dict()["detail"] == "dome"


def test_a_miss_within_rounding_is_met_and_scales_with_the_constraint():
    assert Constraint("c", 1.0 + 0.5 * ROUNDING, 1.0, True, "", 1.0).met
    assert not Constraint("c", 1.0 + 2 * ROUNDING, 1.0, True, "", 1.0).met
    assert Constraint("c", 1.0 + 2 * ROUNDING, 1.0, True, "", 10.0).met
    nan = Constraint("c", math.nan, 1.0, True, "", 1.0)
    assert not nan.met and nan.to_dict()["value"] is None


@pytest.fixture(scope="module")
def evaluated():
    problem = Problem()
    design = problem.baseline_design()
    return problem, design, evaluate_metrics(design, 3.0)


def _window_mm(design):
    """The distance window's margin at every pose, from Eq 3 directly."""
    pitch, roll = design.workspace.grid(3.0)
    d = sensor_distance(
        design.positions_mm, design.reflector.centre_mm, design.reflector.radius_mm, pitch, roll
    )
    ranges = np.array([m.range_mm for m in design.models])
    return np.minimum(d - ranges[:, 0], ranges[:, 1] - d)


def test_worst_case_is_the_worst_pose_and_tightening_moves_the_limit(evaluated):
    problem, design, metrics = evaluated
    plain = {c.name: c for c in worst_case_constraints(problem, design, metrics, {})}
    window = plain["distance_margin_mm"]
    assert window.value == pytest.approx(_window_mm(design).min())
    assert window.limit == problem.distance_margin_mm and not window.upper
    reach = np.hypot(*design.positions_mm[:, :2].T).max() + problem.sensor_backing_mm
    assert plain["sensor_envelope_mm"].value == pytest.approx(reach)
    assert plain["sensor_envelope_mm"].limit == problem.unit_radius_mm
    tight = worst_case_constraints(problem, design, metrics, {"distance_margin_mm": 0.05})
    tight = {c.name: c for c in tight}
    assert tight["distance_margin_mm"].limit == pytest.approx(problem.distance_margin_mm + 0.05)
    assert tight["sensor_envelope_mm"] == plain["sensor_envelope_mm"]


def test_pose_margins_start_with_the_distance_window_at_every_pose(evaluated):
    problem, design, metrics = evaluated
    evaluation = problem.evaluate_design(design, 3.0)
    resolution, margins = pose_margins(problem, evaluation)
    assert resolution.size == 2 * metrics.resolution_pitch_deg.size
    window = (_window_mm(design) - problem.distance_margin_mm).ravel()
    np.testing.assert_allclose(margins[: window.size], window)
    _, tighter = pose_margins(problem, evaluation, {"distance_margin_mm": 0.05})
    np.testing.assert_allclose(tighter[: window.size], window - 0.05)
