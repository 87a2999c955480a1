"""optimise.result: the improvement over the default geometry, the ``predicted`` block of
design.json and its conditions block, on a feasible point of the default problem (1° grid)."""

import dataclasses
import math
from types import SimpleNamespace

import pytest

from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.design import default_design
from reflector_opt.optimiser import Problem, SearchBudget
from reflector_opt.optimiser._result import OptimisationResult
from tests.optimise.points import POINT  # a feasible point of the default problem


@pytest.fixture(scope="module")
def parts():
    problem = Problem()
    evaluation = problem.evaluate(POINT, 1.0)
    baseline = problem.evaluate_design(problem.baseline_design(), 1.0)
    return evaluation, baseline


def _result(evaluation, baseline, **changes):
    found = OptimisationResult(
        design=evaluation.design,
        evaluation=evaluation,
        baseline=baseline,
        seed=3,
        history=[{"generation": 0, "best": 0.2, "spread": 0.1}],
        evaluations={"search": 840, "polish": 60},
        seconds={"search": 12.34567, "polish": 0.1234},
        budget=SearchBudget(),
        tightening={"distance_margin_mm": 0.01},
    )
    return dataclasses.replace(found, **changes)


def test_improvement_is_the_default_over_the_optimised_worst_resolution(parts):
    evaluation, baseline = parts
    result = _result(evaluation, baseline)
    # the same ratios from the metrics computed afresh, outside the optimiser
    mine = evaluate_metrics(evaluation.design, 1.0)
    base = evaluate_metrics(default_design(), 1.0)
    assert result.improvement["pitch"] == pytest.approx(base.worst_pitch_deg / mine.worst_pitch_deg)
    assert result.improvement["roll"] == pytest.approx(base.worst_roll_deg / mine.worst_roll_deg)
    assert result.improvement["worst"] == pytest.approx(
        base.worst_resolution_deg / mine.worst_resolution_deg
    )
    assert result.objective == evaluation.objective and result.metrics is evaluation.metrics


def test_no_baseline_no_improvement_and_no_baseline_block(parts):
    evaluation, _ = parts
    result = _result(evaluation, None)
    assert result.improvement is None
    block = result.predicted()
    assert "baseline" not in block and "improvement" not in block
    assert "baseline" in repr(result) and "not valid here" in repr(result)


def test_the_predicted_block_records_the_search(parts):
    evaluation, baseline = parts
    block = _result(evaluation, baseline).predicted()
    assert block["objective_deg"] == evaluation.objective
    record = block["optimiser"]
    assert record["seed"] == 3 and record["generations"] == 1
    assert record["evaluations"] == {"search": 840, "polish": 60}
    assert record["seconds"] == {"search": 12.346, "polish": 0.123}  # rounded to ms
    assert record["repair_tightening"] == {"distance_margin_mm": 0.01}
    assert record["variables"] == dict(evaluation.values)
    assert block["baseline"]["feasible"] == baseline.feasible
    assert block["improvement"]["worst"] == pytest.approx(
        baseline.metrics.worst_resolution_deg / evaluation.metrics.worst_resolution_deg
    )
    assert "conditions" not in block  # optimised without operating conditions


def test_a_baseline_with_no_resolution_gives_no_ratio(parts):
    evaluation, _ = parts
    unresolved = SimpleNamespace(worst_pitch_deg=math.inf, worst_roll_deg=0.2)
    unresolved.worst_resolution_deg = math.inf
    result = _result(evaluation, SimpleNamespace(metrics=unresolved, budget=None))
    improvement = result.improvement
    assert improvement["pitch"] is None and improvement["worst"] is None
    assert improvement["roll"] == pytest.approx(0.2 / evaluation.metrics.worst_roll_deg)
