"""The optimiser in operating conditions: the budget as objective, a short search against the
white-noise optimum (error budget and built units), bad conditions, and the drift front."""

import json
from functools import cache
from types import SimpleNamespace

import numpy as np
import pytest

from reflector_opt.analysis._budget import (
    drift_sensitivity,
    error_budget,
    thermal_coefficients_of,
)
from reflector_opt.calibration._models import make_model
from reflector_opt.cli import main
from reflector_opt.design import Workspace
from reflector_opt.design._conditions import Conditions
from reflector_opt.model._catalogue import get_part, thermal_coefficients
from reflector_opt.model._operating import OperatingState
from reflector_opt.optimiser import Problem, SearchBudget, optimise
from reflector_opt.optimiser._conditions import (
    binding_sources,
    common_drift_deg,
    pose_totals,
    worst_totals,
)
from reflector_opt.optimiser._drift_front import drift_front
from reflector_opt.optimiser._evaluation import isotropic_worst_deg
from reflector_opt.optimiser._fused_objective import FusedObjective
from reflector_opt.optimiser._sensor_choice import choose_sensor
from reflector_opt.optimiser._variables import values_from_vector
from reflector_opt.tolerance._builtunit import build_unit
from reflector_opt.util._errors import InputError
from tests.searchsettings import SMALL_SEARCH, write_settings

#: Every condition at zero: the budget holds the white noise alone.
QUIET = Conditions.quiet()
#: The conditions of docs/conditions.md's "Designs for the conditions": ±5 K, the rest default
#: but the reference's zero, the 0.1° stated when they were measured (the paper's IMU's class,
#: the default now, is a constant 3° that every design pays alike).
WARM = Conditions().replace(temperature_range_k=5.0, reference_zero_deg=[0.1, 0.1])
#: A search small enough for a test (tests/searchsettings.py's, as objects).
SMALL = SearchBudget(popsize=5, maxiter=8, workers=1)
#: The verification grid of the small search, degrees.
WORKSPACE = Workspace(step_deg=0.5)


def _candidates(problem, count, seed=1):
    """Random points within the bounds, as every design variable."""
    names = problem.free_names
    lower = np.array([problem.search_bounds[n][0] for n in names])
    upper = np.array([problem.search_bounds[n][1] for n in names])
    rng = np.random.default_rng(seed)
    for _ in range(count):
        x = lower + rng.random(len(names)) * (upper - lower)
        yield values_from_vector(names, x, problem.fixed_values)


# --- the objective ---------------------------------------------------------------------------


def test_with_every_condition_at_zero_the_objective_is_the_white_noise_one():
    plain, quiet = Problem(), Problem(conditions=QUIET)
    compared = 0
    for values in _candidates(plain, 40):
        white = plain.evaluate(values, 3.0, checked=False)
        if white.metrics is None or not np.isfinite(white.objective):
            continue
        ours = quiet.evaluate(values, 3.0, checked=False)
        assert ours.budget is not None  # the budget judged it, feasible or not
        if white.objective > 10.0:
            # J nearly singular at some pose: the budget's normal equations lose digits
            # there, or round to no solution (10⁷°: inf, as bad)
            assert ours.objective == np.inf or ours.objective == pytest.approx(
                white.objective, rel=1e-6
            )
            continue
        assert ours.objective == pytest.approx(white.objective, rel=1e-9)
        compared += 1
    assert compared >= 20  # pitch and roll unequal in most: the isotropy factor is the same


@pytest.mark.slow
def test_the_fused_path_judges_a_feasible_candidate_by_its_budget():
    problem = Problem(conditions=WARM)
    values = _designs()[0].evaluation.values  # the white-noise optimum: feasible
    fused = FusedObjective(problem, 3.0).evaluate_values(values)
    assert fused.feasible and fused.budget is not None
    design = problem.design(values, 3.0)
    budget = error_budget(design, WARM, step_deg=3.0)
    pitch, roll = worst_totals(budget)
    assert fused.objective == pytest.approx(isotropic_worst_deg(pitch, roll, 0.25), rel=1e-12)
    assert max(pitch, roll) == pytest.approx(budget.worst_case_deg, rel=1e-12)
    # with every condition at zero it is the fused white-noise objective (the interpolant's
    # derivatives against the budget's differences: 10⁻⁵)
    quiet = FusedObjective(Problem(conditions=QUIET), 3.0).evaluate_values(values)
    white = FusedObjective(Problem(), 3.0).evaluate_values(values)
    assert quiet.objective == pytest.approx(white.objective, rel=1e-4)


def test_pose_totals_and_binding_sources_by_hand():
    budget = error_budget(Problem().baseline_design(), WARM, step_deg=5.0)
    totals = pose_totals(budget)
    maps = budget.maps
    i, j = 3, 5
    by_hand = np.sqrt(sum(m[i, j, 1] ** 2 for m in maps.values()))
    assert totals[i, j, 1] == pytest.approx(by_hand, rel=1e-12)
    binding = binding_sources(budget)
    assert binding["total_deg"] == pytest.approx(budget.worst_case_deg, rel=1e-12)
    assert sum(binding["shares"].values()) == pytest.approx(1.0, rel=1e-9)
    assert list(binding["sources_deg"]) == sorted(
        binding["sources_deg"], key=lambda k: -binding["sources_deg"][k]
    )
    assert "form" not in binding["sources_deg"]  # left out: zero


def test_a_tie_at_mirrored_poses_picks_the_first_in_the_grid_whatever_the_last_bits():
    """A mirror-symmetric design's worst total ties at mirrored poses (roll ±15°); the
    binding pose must not depend on which of them rounding makes larger."""
    pitch, roll = np.meshgrid([-15.0, 0.0, 15.0], [-15.0, 0.0, 15.0], indexing="ij")
    temperature = np.stack([0.1 + 0.01 * np.abs(pitch + roll), 0.2 + 0.01 * np.abs(roll)], -1)
    noise = np.full_like(temperature, 0.05)
    budget = SimpleNamespace(
        pitch_deg=pitch, roll_deg=roll, maps={"temperature": temperature, "noise": noise}
    )
    assert binding_sources(budget)["pose_deg"] == [-15.0, -15.0]  # ties with (15, 15)
    temperature[2, 2, 0] *= 1 + 4e-16  # the last of the tied poses larger by one rounding step
    assert binding_sources(budget)["pose_deg"] == [-15.0, -15.0]
    temperature[2, 2, 0] *= 1 + 1e-6  # larger by more than rounding: it is the worst
    assert binding_sources(budget)["pose_deg"] == [15.0, 15.0]


# --- a short search in the conditions against the white-noise optimum -------------------------


@cache
def _designs():
    """The white-noise optimum and the design optimised at ±5 K, by the same short search."""
    white = optimise(Problem(workspace=WORKSPACE), seed=0, budget=SMALL)
    warm = optimise(Problem(workspace=WORKSPACE, conditions=WARM), seed=0, budget=SMALL)
    return white, warm


def test_a_short_search_in_the_conditions_beats_the_white_noise_optimum_there():
    white, warm = _designs()
    assert warm.evaluation.feasible
    assert all(c.met for c in warm.evaluation.constraints)  # printed walls included
    assert "printed_wall_mm" in warm.evaluation.constraints_dict()
    ours = error_budget(warm.design, WARM).worst_case_deg  # the full 1° grid
    theirs = error_budget(white.design, WARM).worst_case_deg
    assert ours < 0.8 * theirs
    block = warm.design.predicted.conditions
    assert block.worst_case_deg == pytest.approx(ours, rel=1e-12)
    assert block.grid_deg == {"search": 3.0, "polish": 2.0, "verified": 1.0}
    assert block.conditions["temperature_range_k"] == 5.0
    assert "conditions" not in white.design.predicted.to_dict()  # nothing new without conditions
    # and it pays in white noise: the white-noise optimum resolves better
    assert white.metrics.worst_resolution_deg < warm.metrics.worst_resolution_deg


def _temperature_error_on_built_units(design):
    """Largest shift of a poly5 calibration's estimate at ±5 K over built units (exact optics,
    as-built geometry), on a grid that holds the workspace's corners, degrees."""
    thermal = thermal_coefficients_of(design.models)
    pitch, roll = np.meshgrid(np.linspace(-15, 15, 13), np.linspace(-15, 15, 13), indexing="ij")
    angles = np.column_stack([pitch.ravel(), roll.ravel()])
    worst = 0.0
    for index in (0, 1):
        unit = build_unit(design, index, seed=11)
        calibration = make_model("poly5").fit(unit.volts(angles[:, 0], angles[:, 1]), angles)
        bench = calibration.predict(unit.volts(angles[:, 0], angles[:, 1]))
        for dt in (5.0, -5.0):
            state = OperatingState(delta_t_k=dt, thermal=thermal)
            hot = calibration.predict(unit.volts(angles[:, 0], angles[:, 1], state))
            worst = max(worst, float(np.abs(hot - bench).max()))
    return worst


def test_built_units_of_the_conditions_design_drift_less_with_temperature():
    white, warm = _designs()
    ours = _temperature_error_on_built_units(warm.design)
    theirs = _temperature_error_on_built_units(white.design)
    assert ours < 0.7 * theirs
    # and each is what the budget's temperature term says, within a third
    for result, measured in ((warm, ours), (white, theirs)):
        term = error_budget(result.design, QUIET.replace(temperature_range_k=5.0))
        predicted = term.sources["temperature"]
        assert measured == pytest.approx(
            max(predicted.pitch_max_deg, predicted.roll_max_deg), rel=0.35
        )


# --- options, config and command line --------------------------------------------------------


def test_problem_refuses_bad_conditions_and_drift_limits():
    with pytest.raises(InputError, match=r"^conditions: expected Conditions"):
        Problem(conditions={"temperature_range_k": 5})
    for bad in (0.0, -1.0, float("nan"), True):
        with pytest.raises(InputError, match=r"^drift_limit_deg:"):
            Problem(drift_limit_deg=bad)


@pytest.mark.parametrize(
    ("where", "text", "fragment"),
    [
        ("config", "[conditions]\ntemperature_range_k = -1.0\n", "temperature_range_k"),
        ("config", "[conditions]\ntemperture_range_k = 5.0\n", "temperture_range_k"),
        ("config", '[conditions]\ndrive = "pulsed"\n', "drive"),
        ("file", "[conditions]\ntemperature_range_k = 298.0\n", "temperature_range_k"),
        ("file", "[conditions]\nambient_mv = 0.001\n", "ambient_mv"),
        ("file", "[conditions]\nreference_zero_deg = [0.1]\n", "reference_zero_deg"),
        ("missing", "", "cannot read"),
    ],
)
def test_bad_conditions_exit_2_name_the_key_and_write_nothing(
    tmp_path, capsys, where, text, fragment
):
    out = tmp_path / "out"
    args = ["optimise", "-o", str(out), "--no-report", "--quiet"]
    if where == "config":
        args += ["--config", write_settings(tmp_path, SMALL_SEARCH + text)]
    else:
        path = tmp_path / "cond.toml"
        if where == "file":
            path.write_text(text, encoding="utf-8")
        args += ["--conditions", str(path)]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("reflector-opt optimise: error:")
    assert fragment in err[0]
    assert not out.exists()


@pytest.mark.slow
def test_the_command_optimises_in_the_conditions_and_says_what_binds(tmp_path, capsys):
    out = tmp_path / "out"
    path = tmp_path / "cond.toml"
    path.write_text(  # WARM's
        "[conditions]\ntemperature_range_k = 5.0\nreference_zero_deg = [0.1, 0.1]\n",
        encoding="utf-8",
    )
    # the drift front's one level asks 5 % of the white-noise optimum's drift: no design
    settings = write_settings(tmp_path, SMALL_SEARCH + "[pareto]\ndrift_fractions = [0.05]\n")
    args = ["optimise", "--config", settings, "--conditions", str(path), "-o", str(out)]
    args += ["--read-out", "stated"]  # the library's search, in the conditions' own read-out
    assert main([*args, "--drift-front", "--no-report", "--quiet"]) == 0
    doc = json.loads((out / "design.json").read_text(encoding="utf-8"))
    block = doc["predicted"]["conditions"]
    _, warm = _designs()  # the same search: the same design
    assert block["worst_case_deg"] == pytest.approx(
        warm.design.predicted.conditions.worst_case_deg, rel=1e-9
    )
    assert block["baseline"]["worst_case_deg"] > 0
    text = capsys.readouterr().out
    assert "in use (±5 K, dc drive" in text
    assert f"worst case {block['worst_case_deg']:.4f}°" in text
    # the median over the workspace's poses, both designs, and their ratio, as written
    median, base_median = block["median_deg"], block["baseline"]["median_deg"]
    assert 0 < median <= block["worst_case_deg"]
    assert block["improvement_median"] == pytest.approx(base_median / median, rel=1e-12)
    assert f"{block['improvement_median']:.2f}× (median)" in text
    # the headline comes first: in use before the geometry, the floor beside it
    assert text.index("in use (") < text.index("reflector: radius")
    floor = max(
        doc["predicted"]["metrics"]["resolution_deg"][k] for k in ("pitch_worst", "roll_worst")
    )
    assert f"white-noise floor {floor:.4f}°" in text
    assert "temperature" in text.split("at its worst")[1]
    front = json.loads((out / "drift_front.json").read_text(encoding="utf-8"))
    assert front == doc["predicted"]["drift_front"]
    first, strict = front["points"]
    assert first["drift_limit_deg"] is None and not strict["feasible"]
    assert front["reference"]["worst_case_deg"] == pytest.approx(block["worst_case_deg"])
    assert "drift front (seed 0" in text and "no design:" in text


# --- the drift front -------------------------------------------------------------------------


@pytest.mark.slow
def test_the_drift_front_is_non_dominated_and_keeps_its_limits():
    problem = Problem(workspace=WORKSPACE, conditions=WARM)
    warm = _designs()[1]
    front = drift_front(problem, (0.7, 0.05), seed=0, budget=SMALL, reference=warm)
    first, loose, strict = front.points
    assert first.drift_limit_deg is None and first.kept_from is None
    assert first.objective_deg == pytest.approx(_designs()[0].objective, rel=1e-9)
    assert loose.drift_limit_deg == pytest.approx(0.7 * first.drift_deg)
    assert not strict.feasible and strict.reason  # 5 % of the drift: no design
    assert front.reference.worst_case_deg == pytest.approx(
        error_budget(warm.design, WARM).worst_case_deg, rel=1e-9
    )
    kept = front.front_points
    assert len(kept) >= 2
    for p in kept:
        for q in kept:
            assert not (
                q.drift_deg <= p.drift_deg
                and q.objective_deg <= p.objective_deg
                and (q.drift_deg, q.objective_deg) != (p.drift_deg, p.objective_deg)
            )
    # the limit holds on the level's design itself, by the budget's own drift sensitivity,
    # whichever run found it; and its total error in the conditions is the budget's
    assert loose.feasible
    design = problem.design(loose.values)
    common = drift_sensitivity(design)["common"]
    assert max(common.pitch_rms_deg, common.roll_rms_deg) <= loose.drift_limit_deg * (1 + 1e-6)
    assert common_drift_deg(design) == pytest.approx(loose.drift_deg, rel=1e-9)
    assert loose.worst_case_deg == pytest.approx(
        error_budget(design, WARM).worst_case_deg, rel=1e-9
    )
    # the trade: less drift costs white-noise resolution
    assert loose.drift_deg < first.drift_deg and loose.objective_deg > first.objective_deg
    doc = front.to_dict()
    assert doc["format"] == "reflector-opt/drift-front@1" and doc["conditions"]["drive"] == "dc"


# --- the sensor part in the conditions ---------------------------------------------------------


@pytest.mark.slow
def test_parts_are_ranked_by_their_total_error_with_their_own_temperature_figures():
    problem = Problem(workspace=WORKSPACE, conditions=WARM)
    choice = choose_sensor(problem, [get_part("NJL5901R-2"), get_part("VCNT2020")], budget=SMALL)
    ranked = [r for r in choice.record["ranking"] if r["status"] == "ranked"]
    assert [r["rank"] for r in ranked] == [1, 2]
    assert ranked[0]["objective_deg"] <= ranked[1]["objective_deg"]
    assert "worst-case total error in the conditions" in choice.record["criteria"]
    assert choice.record["conditions"]["temperature_range_k"] == 5.0
    for row in ranked:
        figures = thermal_coefficients(row["part"])
        assert row["thermal_coefficients"]["led_output_per_k"] == figures.led_output_per_k
        assert row["worst_case_deg"] > 0
    design = choice.result.design
    assert choice.result.evaluation.budget.worst_case_deg == pytest.approx(
        error_budget(design, WARM).worst_case_deg, rel=1e-9
    )
    assert ranked[0]["worst_case_deg"] == pytest.approx(
        error_budget(design, WARM).worst_case_deg, rel=1e-9
    )
