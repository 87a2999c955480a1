"""The size-accuracy frontier: bearings per size, the problem of a point, a sample point
against an independent single-envelope optimisation, and the smallest row."""

import dataclasses
import math

import numpy as np
import pytest

from reflector_opt import workflow
from reflector_opt.analysis._budget import error_budget
from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.design import Workspace
from reflector_opt.design._bearings import get_bearing, shipped_bearings
from reflector_opt.design._conditions import Conditions
from reflector_opt.design._parts import CadParameters, design_parameters
from reflector_opt.model._catalogue import get_part
from reflector_opt.optimiser._problem import Problem
from reflector_opt.optimiser._search import SearchBudget, optimise
from reflector_opt.optimiser._size import (
    SizeStudy,
    _failed,
    _judged,
    _monotone,
    choose_bearing,
    frontier_point,
    in_use_floor_deg,
    judged_deg,
    point_config,
    size_frontier,
    size_limits,
    size_problem,
    smallest_row,
)
from reflector_opt.util._errors import InputError
from tests.workflow.test_smallest import POINT_20MM

SMALL = Workspace((-11.0, 11.0), (-11.0, 11.0), step_deg=0.5)
TINY = SearchBudget(popsize=5, maxiter=8, workers=1)


def test_the_bearing_of_a_point_is_the_smallest_od_whose_tilt_covers_the_workspace():
    assert choose_bearing(shipped_bearings(), SMALL, 20.0).name == "GE4E"
    # ±9° asks arccos(cos²9°) = 12.7°: both bearings permit it, the 12 mm OD is chosen
    assert choose_bearing(shipped_bearings(), Workspace((-9, 9), (-9, 9)), 20.0).name == "GE4E"
    only_ge6 = [get_bearing("GE6E")]
    # its stop (29.6°), not its rated 13°, limits: ±11° (15.5°) is accepted, ±22° (30.7°) not
    assert choose_bearing(only_ge6, SMALL, 20.0).name == "GE6E"
    wide = Workspace((-22.0, 22.0), (-22.0, 22.0))
    with pytest.raises(InputError, match=r"up to 30.7°; the most any bearing permits is 29.6°"):
        choose_bearing(only_ge6, wide, 20.0)
    with pytest.raises(InputError, match="GE4E, is 12 mm across, not inside a 12 mm unit"):
        choose_bearing(shipped_bearings(), SMALL, 12.0)


def test_the_problem_of_a_point_names_the_bearing_its_layout_takes_the_widths_of():
    problem = size_problem(Problem(workspace=SMALL), get_part("VCNT2020"), 18.0, "GE4E")
    assert problem.mechanics.bearing == "GE4E"
    assert (problem.mechanics.bearing_bore_mm, problem.mechanics.bearing_od_mm) == (4.0, 12.0)
    # the CAD parameters leave the widths and the tendon circle to the design's layout
    assert problem.cad.bearing_ball_diameter_mm is None and problem.cad.tendon_radius_mm is None
    params = design_parameters(problem.cad, problem.baseline_design())
    assert (params.bearing_inner_width_mm, params.bearing_outer_width_mm) == (5.0, 3.0)
    assert params.bearing_ball_diameter_mm == 8.0  # SKF GE 4 E: B 5, C 3, dk 8
    assert params.tendon_radius_mm == pytest.approx(9.0 - (11.0 - 9.8))
    assert problem.sensor.name == "VCNT2020"
    assert problem.search_bounds["sensor_radius_mm"][1] == pytest.approx(9.0 - 1.0 - 0.2)


def test_a_study_refuses_bearing_widths_or_a_tendon_circle_given_for_every_size():
    cad = CadParameters(tendon_radius_mm=9.8)
    with pytest.raises(InputError, match=r"cad\.tendon_radius_mm: the frontier lays each size"):
        SizeStudy(Problem(workspace=SMALL, cad=cad), shipped_bearings())
    # a count of starts no search takes is refused here, not as every point's failure
    with pytest.raises(InputError, match="starts"):
        SizeStudy(Problem(workspace=SMALL), shipped_bearings(), starts=0)


def test_a_frontier_point_is_an_independent_optimisation_at_its_size(tmp_path):
    study = SizeStudy(Problem(workspace=SMALL), shipped_bearings(), 22.0, 2.0, 2.0, None, 0, TINY)
    part = get_part("VCNT2020")
    study = dataclasses.replace(study, largest_mm=20.0)
    points = size_frontier(dataclasses.replace(study, largest_mm=22.0), [part])[:2]
    (row22, _, _), (row20, _, _) = points
    assert row22["status"] == row20["status"] == "feasible"
    assert row20["unit_diameter_mm"] == 20.0 and row20["bearing"] == "GE4E"
    config = tmp_path / "point.toml"
    config.write_text(point_config(study, row20))
    assert config.read_text().startswith("# reflector-opt optimise --config THIS --sensor VCNT2020")
    options = workflow.OptimiseOptions(
        config=str(config), sensor="VCNT2020", report=False, starts=3, objective="resolution"
    )  # the study's problem states no conditions: its points are white-noise optima
    run = workflow.optimise(options).write(tmp_path / "o")
    assert run.result.objective == pytest.approx(row20["objective_deg"], rel=5e-3)
    assert run.design.mechanics.unit_diameter_mm == 20.0
    assert run.design.mechanics.bearing == "GE4E"
    # an independent search at that size (another seed, one start): the point, the best of
    # three, is within 0.5 % of it or better
    problem = size_problem(study.problem, part, 20.0, "GE4E")
    other = optimise(problem, seed=1, budget=TINY)
    assert row20["objective_deg"] <= other.objective * 1.005


@pytest.mark.parametrize(
    ("reason", "name"),
    [
        (
            "no design passed verification on the 0.5° grid: separation_sigma is 1.1 σ_V",
            "separation_sigma",
        ),
        ("VCNT2020 (2 × 2.5 × 0.8 mm): wall: with the sensors at most", "wall"),
        (
            "no design within the bounds meets the constraints; the closest: wall_mm is 0.79 mm",
            "wall_mm",
        ),
    ],
)
def test_the_binding_of_a_size_no_design_fits_is_named(reason, name):
    assert _failed(reason, "VCNT2020") == name


def test_the_smallest_size_of_each_part_and_what_fails_below_it():
    rows = [
        {"part": "A", "unit_diameter_mm": 22.0, "status": "feasible"},
        {"part": "A", "unit_diameter_mm": 20.0, "status": "feasible"},
        {"part": "A", "unit_diameter_mm": 18.0, "status": "infeasible", "binding": "wall_mm"},
        {"part": "A", "unit_diameter_mm": 19.5, "status": "infeasible", "binding": "separation"},
        {"part": "B", "unit_diameter_mm": 22.0, "status": "infeasible", "binding": "wall"},
    ]
    for row in rows[2:]:
        row["reason"] = f"{row['binding']} short"
    a, b = size_limits(rows)
    assert (a["smallest_mm"], a["fails_at_mm"], a["binding"]) == (20.0, 19.5, "separation")
    assert a["reason"] == "separation short"
    assert (b["part"], b["smallest_mm"], b["fails_at_mm"], b["binding"]) == (
        "B",
        None,
        22.0,
        "wall",
    )


def test_the_smallest_row_and_a_target_below_every_point():
    rows = [
        {"part": "A", "unit_diameter_mm": 22.0, "status": "feasible", "objective_deg": 0.05},
        {"part": "A", "unit_diameter_mm": 20.0, "status": "feasible", "objective_deg": 0.08},
        {"part": "B", "unit_diameter_mm": 20.0, "status": "feasible", "objective_deg": 0.07},
        {"part": "B", "unit_diameter_mm": 19.5, "status": "infeasible", "reason": "wall"},
    ]
    assert smallest_row(rows, 0.1)["part"] == "B"
    assert smallest_row(rows, 0.06)["unit_diameter_mm"] == 22.0
    with pytest.raises(
        InputError, match=r"0.01° is below what any part reaches: the best is 0.05°"
    ):
        smallest_row(rows, 0.01)


def test_a_larger_size_keeps_the_smaller_neighbours_design_when_its_own_search_fails():
    # 20 mm searched; 20.5 mm given as a failed search: the monotone pass judges the 20 mm
    # design under the 20.5 mm problem and keeps it (a larger envelope holds it)
    study = SizeStudy(Problem(workspace=SMALL), shipped_bearings(), budget=TINY)
    part = get_part("VCNT2020")
    row, values, result = frontier_point(study, part, 20.0)
    assert row["status"] == "feasible"
    failed = {"part": part.name, "unit_diameter_mm": 20.5, "bearing": "GE4E"}
    failed |= {"status": "infeasible", "reason": "searched too little", "binding": "x"}
    found = {20.0: (values, result, row), 20.5: (None, None, failed)}
    _monotone(study, part, found)
    values_big, carried, big = found[20.5]
    assert big["status"] == "feasible" and big["carried_from_mm"] == 20.0
    assert values_big == pytest.approx(values)
    assert big["objective_deg"] <= row["objective_deg"] * (1 + 1e-9)
    # independently: the carried design judged by the 20.5 mm problem meets every constraint
    problem = size_problem(study.problem, part, 20.5, "GE4E")
    assert carried.design.mechanics.unit_diameter_mm == 20.5
    judged = problem.check_printed(problem.evaluate_design(carried.design))
    assert judged.feasible
    assert judged.objective == pytest.approx(big["objective_deg"], rel=1e-9)
    # a worse design is not carried over a better own search
    found[20.5] = (values_big, carried, {**big, "objective_deg": 0.0, "carried_from_mm": None})
    _monotone(study, part, found)
    assert found[20.5][2]["carried_from_mm"] is None


def test_the_in_use_floor_is_the_reference_zero_and_lag_the_budget_holds_at_the_centre():
    """In the default conditions: the imu-lpms-b's assumed 1.0° zero and a lag of
    5 °/s × 2 ms = 0.01°, hypot(1.0, 0.01) = 1.00005°; the budget's reference and latency
    sources give exactly that at the centre pose (no twist there) and no less anywhere."""
    conditions = Conditions()
    assert in_use_floor_deg(conditions) == pytest.approx(math.hypot(1.0, 0.01), rel=1e-12)
    budget = error_budget(POINT_20MM, conditions, step_deg=1.0)
    both = np.hypot(budget.maps["reference"], budget.maps["latency"])  # (pitch, roll, angle)
    centre = (budget.pitch_deg == 0) & (budget.roll_deg == 0)
    assert both[centre].max() == pytest.approx(in_use_floor_deg(conditions), rel=1e-9)
    assert both.min() >= in_use_floor_deg(conditions) * (1 - 1e-12)
    assert budget.worst_case_deg >= in_use_floor_deg(conditions)
    # a better reference lowers it: the LPMS-B2's published 0.5°, an encoder rig's 5.49″
    assert in_use_floor_deg(conditions.replace(angle_reference="imu-lpms-b2")) == pytest.approx(
        math.hypot(0.5, 0.01)
    )
    encoder = conditions.replace(angle_reference="encoder", angular_speed_deg_s=0.0)
    assert in_use_floor_deg(encoder) == pytest.approx(5.49 / 3600)


def test_a_target_below_the_in_use_floor_is_refused_before_any_search():
    problem = Problem(workspace=SMALL, conditions=Conditions())
    with pytest.raises(InputError) as caught:
        SizeStudy(problem, shipped_bearings(), target_deg=0.5, budget=TINY)
    message = str(caught.value)
    assert message.startswith("--target-deg: 0.5° is below the in-use floor of 1° ")
    assert "imu-lpms-b's 1° class (assumed)" in message
    assert '"imu-lpms-b2"' in message and "reference_zero_deg" in message
    # with a stated reference of 0.1° the same target is searched for; without conditions
    # (the white-noise objective) no floor applies
    stated = Conditions().replace(reference_zero_deg=[0.1, 0.1])
    SizeStudy(dataclasses.replace(problem, conditions=stated), shipped_bearings(), target_deg=0.5)
    SizeStudy(Problem(workspace=SMALL), shipped_bearings(), target_deg=0.05)


def test_in_use_the_target_judges_the_worst_case_not_the_white_noise_objective():
    """Both sizes meet 0.1° in white noise; in use only the 22 mm unit meets 1.1°, so it is
    the smallest meeting the target although the 20 mm unit's objective is below it."""
    rows = [
        {"part": "A", "unit_diameter_mm": 22.0, "status": "feasible", "objective_deg": 1.09}
        | {"worst_case_deg": 1.08, "white_noise_deg": 0.06},
        {"part": "A", "unit_diameter_mm": 20.0, "status": "feasible", "objective_deg": 1.05}
        | {"worst_case_deg": 1.13, "white_noise_deg": 0.07},
    ]
    assert smallest_row(rows, 1.1)["unit_diameter_mm"] == 22.0
    with pytest.raises(InputError, match=r"the best is 1.08° \(A at 22 mm\), the least in-use"):
        smallest_row(rows, 1.0)
    plain = [{k: v for k, v in r.items() if k != "worst_case_deg"} for r in rows]
    assert smallest_row(plain, 1.1)["unit_diameter_mm"] == 20.0  # judged by the objective


def test_a_point_in_conditions_records_its_in_use_worst_case_beside_the_white_noise_floor(
    monkeypatch,
):
    """The row of a design judged in the default conditions against the budget and the
    metrics computed on their own (the largest bearing, which needs the design's variables,
    left out)."""
    monkeypatch.setattr("reflector_opt.optimiser._size._largest_bearing", lambda *a: None)
    conditions = Conditions()
    study = SizeStudy(Problem(workspace=SMALL, conditions=conditions), shipped_bearings())
    part = get_part("VCNT2020")
    problem = size_problem(study.problem, part, 20.0, "GE4E")
    row = _judged(study, part, 20.0, problem.evaluate_design(POINT_20MM))
    alone = error_budget(POINT_20MM, conditions, step_deg=1.0).worst_case_deg
    assert row["worst_case_deg"] == pytest.approx(alone, rel=1e-9)
    metrics = evaluate_metrics(POINT_20MM)
    floor = max(metrics.worst_pitch_deg, metrics.worst_roll_deg)
    assert row["white_noise_deg"] == pytest.approx(floor, rel=1e-9)
    assert row["worst_case_deg"] > 5 * row["white_noise_deg"]  # the in-use error, not noise
    assert judged_deg(row) == row["worst_case_deg"]


def test_a_white_noise_point_reports_its_worst_case_in_the_stated_conditions(monkeypatch):
    """``--objective resolution --conditions X``: the search has no conditions, the row its
    worst case in X (the budget on its own) beside the objective the target judges, and the
    study of ``smallest`` carries X."""
    from reflector_opt.workflow._smallest import SmallestOptions, _study

    monkeypatch.setattr("reflector_opt.optimiser._size._largest_bearing", lambda *a: None)
    stated = Conditions(angle_reference="encoder", temperature_range_k=5.0)
    study = SizeStudy(Problem(workspace=SMALL), shipped_bearings(), reported_in=stated)
    part = get_part("VCNT2020")
    problem = size_problem(study.problem, part, 20.0, "GE4E")
    row = _judged(study, part, 20.0, problem.evaluate_design(POINT_20MM))
    alone = error_budget(POINT_20MM, stated, step_deg=1.0).worst_case_deg
    assert row["objective"] == "resolution"
    assert row["worst_case_deg"] == pytest.approx(alone, rel=1e-9)
    assert alone != pytest.approx(error_budget(POINT_20MM, Conditions()).worst_case_deg, rel=0.01)
    assert judged_deg(row) == row["objective_deg"] != row["worst_case_deg"]
    assert judged_deg(row | {"objective": "in-use"}) == row["worst_case_deg"]
    plain = SizeStudy(Problem(workspace=SMALL), shipped_bearings())
    assert _judged(plain, part, 20.0, problem.evaluate_design(POINT_20MM))["worst_case_deg"] is None
    options = SmallestOptions(target_deg=0.1, workspace_deg=11.0, objective="resolution")
    assert _study(options)[0].reported_in == Conditions()
    assert _study(SmallestOptions(target_deg=1.5, workspace_deg=11.0))[0].reported_in is None
