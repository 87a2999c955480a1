"""A candidate's evaluation: objective, feasibility, penalties, the worst case over the surface."""

import math

import pytest

from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.design import default_design
from reflector_opt.optimiser import (
    Problem,
    objective_value,
)
from reflector_opt.optimiser._evaluation import PENALTY
from tests.optimise.points import POINT


def test_objective_is_worst_case_times_isotropy():
    metrics = evaluate_metrics(default_design(), 3.0)
    wp, wr = metrics.worst_pitch_deg, metrics.worst_roll_deg
    assert objective_value(metrics, 0.0) == pytest.approx(max(wp, wr))
    expected = max(wp, wr) * (1 + 0.5 * abs(math.log(wp / wr)))
    assert objective_value(metrics, 0.5) == pytest.approx(expected)


def test_feasible_candidates_beat_infeasible_ones():
    problem = Problem()
    good = problem.evaluate(POINT, 3.0)
    assert good.feasible and good.penalised == good.objective < 1.0
    close = problem.evaluate({**POINT, "gap_mm": 0.65}, 3.0)  # too close at some poses
    assert not close.feasible
    broken = {c.name: c for c in close.constraints if not c.met}
    assert "distance_margin_mm" in broken
    assert close.penalised == pytest.approx(
        PENALTY + sum(-c.margin / c.scale for c in broken.values())
    )
    assert close.worst_constraint().name in close.describe_failure()


def test_invalid_candidates_score_without_crashing():
    problem = Problem()
    no_sphere = problem.evaluate({**POINT, "gap_mm": 20.0}, 3.0)  # r_s ≤ 0
    assert no_sphere.error and "gap_mm" in no_sphere.error
    colliding = problem.evaluate({**POINT, "sensor_radius_mm": 9.0, "centre_along_mm": 2.0}, 3.0)
    assert not colliding.feasible
    assert no_sphere.penalised > colliding.penalised > PENALTY


def test_zero_offset_is_infeasible_not_an_error():
    flat = {**POINT, "centre_along_mm": 0.0, "centre_z_mm": 0.0, "sensor_height_mm": 0.0}
    e = Problem().evaluate(flat, 3.0)
    assert e.metrics is not None and not e.metrics.sensitive
    assert e.objective == math.inf
    assert not e.feasible and e.worst_constraint().name == "fold_fraction"


def test_an_interval_of_f_is_judged_by_its_worst_case():
    """The evaluation over [0, 1] is the worst of the evaluations at 0, 0.5 and 1."""
    from dataclasses import replace

    problem = Problem(specular_fraction_range=(0.0, 1.0))
    base = problem.baseline_design()
    robust = problem.evaluate_design(base, 3.0)
    single = [
        Problem().evaluate_design(
            base.replace(reflector=replace(base.reflector, specular_fraction=f)), 3.0
        )
        for f in (0.0, 0.5, 1.0)
    ]
    assert robust.penalised == max(e.penalised for e in single)
    assert robust.design is base
