"""Planning the temperatures of a calibration: the command's plan checked on a unit it did not
see, the recommendation, bad options."""

import contextlib
import io
import json
from pathlib import Path

import numpy as np
import pytest

from reflector_opt.calibration._files import write_calibration_csv
from reflector_opt.calibration._plans import make_plan
from reflector_opt.calibration._unit_calibration import calibrate_csv
from reflector_opt.cli import main
from reflector_opt.design._design import load_design
from reflector_opt.model._operating import OperatingState
from reflector_opt.tolerance._builtunit import build_unit
from reflector_opt.tolerance._planning import PlanPrediction, PlanStudy
from reflector_opt.tolerance._thermalplan import (
    COST_ROWS,
    ThermalPrediction,
    ThermalStudy,
    allowed_error_k,
    plan_temperature,
    plan_to_extend,
    recommend_thermal,
    thermometer_costs,
)
from reflector_opt.util._errors import InputError
from reflector_opt.workflow._plan_text import thermometer_lines

DATA = Path(__file__).resolve().parents[1] / "data"


def _rms(error):
    return np.sqrt(np.mean(error**2, axis=0))


#: Units the plan is checked on (seed 0), none of them the study's.
CHECKED_UNITS = (1, 2, 3, 4)


@pytest.fixture(scope="module")
def temperature_plan(tmp_path_factory):
    """The command's plan with its temperature plan (one study unit, ±10 K): its folder and
    what it printed."""
    out = tmp_path_factory.mktemp("thermal") / "plan"
    argv = ["plan-calibration", "--forms", "auto", "--patterns", "grid", "--sizes", "100"]
    argv += ["--units", "1", "--within", "0.3", "--temperature-range", "10", "-o", str(out)]
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert main(argv) == 0
    return out, printed.getvalue()


def _compensated_over_white(design, index, plan_folder, folder):
    """Worst RMS error at ΔT = −10, 0, +10 K of unit ``index`` (seed 0) calibrated on the
    plan at 25 °C and plan_temperature.csv's poses at their temperatures, over its error at
    T0 calibrated on the plan at T0 alone (its white-noise error), per angle."""
    base = np.genfromtxt(plan_folder / "plan.csv", delimiter=",", names=True)
    extra = np.genfromtxt(plan_folder / "plan_temperature.csv", delimiter=",", names=True)
    unit, rng = build_unit(design, index, seed=0), np.random.default_rng(77 + index)
    recorded = [unit.record(np.column_stack([base["pitch_deg"], base["roll_deg"]]), rng)]
    temperature = [np.full(len(base), 25.0)]
    for dt in np.unique(extra["temperature_change_k"]):
        at = extra[extra["temperature_change_k"] == dt]
        poses = np.column_stack([at["pitch_deg"], at["roll_deg"]])
        recorded.append(unit.record(poses, rng, state=OperatingState(delta_t_k=float(dt))))
        temperature.append(np.full(len(at), 25.0 + dt))
    path = folder / f"data_{index}.csv"
    volts = np.vstack([r.volts for r in recorded])
    angles = np.vstack([r.angles_deg for r in recorded])
    write_calibration_csv(path, ["u"] * len(volts), volts, angles, np.concatenate(temperature))
    (compensated,) = calibrate_csv(path, "auto", folds=0)
    t0 = recorded[0]  # the same plan at T0 alone: the unit's white-noise error
    write_calibration_csv(
        folder / f"t0_{index}.csv", ["u"] * len(t0.volts), t0.volts, t0.angles_deg
    )
    (plain,) = calibrate_csv(folder / f"t0_{index}.csv", "auto", folds=0)
    truth = rng.uniform(-15, 15, (3000, 2))
    ratios = []
    for dt in (-10.0, 0.0, 10.0):
        check = unit.record(truth, np.random.default_rng(78), 0.0, OperatingState(delta_t_k=dt))
        error = compensated.model.predict(check.volts, np.full(len(truth), 25.0 + dt)) - truth
        if dt == 0.0:
            white = _rms(plain.model.predict(check.volts) - truth)
        ratios.append(_rms(error))
    return np.max(np.array(ratios) / white)


@pytest.mark.slow
def test_the_written_plan_holds_on_units_the_study_did_not_see(design, temperature_plan, tmp_path):
    """Calibrated on the written plan, units the one-unit study did not see keep their error
    at ±10 K within 2.5× their white-noise error at T0 (uncompensated about 6×); the worst of
    the six ratios (±10 K and T0, two angles) averages 1.44 over units 1–12 (sd 0.23, largest
    2.03; the study predicted 1.16 on its own unit). "Within 1.4×" held on unit 1 and failed
    on six of twelve. Four units average over 1.8 with probability under 0.1 %."""
    folder, printed = temperature_plan
    thermal = json.loads((folder / "plan.json").read_text())["temperature"]
    pick = thermal["recommended"]
    assert pick is not None and f"then {pick['n_poses']} Sobol poses at T0" in printed
    assert max(max(r) for r in thermal["uncompensated_ratio"]) > 4  # ~6x at ±10 K
    extra = np.genfromtxt(folder / "plan_temperature.csv", delimiter=",", names=True)
    assert len(extra) == pick["extra_poses"]
    worst = [_compensated_over_white(design, index, folder, tmp_path) for index in CHECKED_UNITS]
    assert np.max(worst) < 2.5 and np.mean(worst) < 1.8, worst


def _prediction(extra_per_temperature, worst, changes=(10.0,)):
    rms = np.full((5, 2), 0.1)
    rms[0, 0] = 0.1 * worst
    layout = "warm" if len(changes) == 1 else "both"
    return ThermalPrediction(layout, extra_per_temperature, changes, rms, np.array([0.1, 0.1]))


def test_the_fewest_extra_poses_within_the_margin_are_recommended():
    predictions = [
        _prediction(10, 1.3),
        _prediction(25, 1.08),
        _prediction(10, 1.05, (-10.0, 10.0)),  # 20 poses in all: fewer than 25
        _prediction(50, 1.01),
    ]
    study = ThermalStudy(
        10.0,
        "auto",
        "grid",
        100,
        np.linspace(-10, 10, 5),
        np.array([0.1, 0.1]),
        np.full((5, 2), 0.6),
        predictions,
        1,
        0,
    )
    assert recommend_thermal(study).extra_poses == 20
    assert recommend_thermal(study, within=0.02).n_poses == 50
    assert recommend_thermal(study, within=0.001) is None
    assert json.loads(json.dumps(study.to_dict()))["uncompensated_ratio"][0] == pytest.approx(
        [6, 6]
    )


def test_bad_requests_are_refused(design, capsys):
    with pytest.raises(InputError, match="temperature change: expected 1 to 60 K"):
        plan_temperature(design, np.zeros((4, 2)), change_k=0.5)
    with pytest.raises(InputError, match="layouts: unknown cold"):
        plan_temperature(design, np.zeros((4, 2)), layouts=("cold",))
    assert main(["plan-calibration", "--temperature-range", "100"]) == 2
    assert "--temperature-range: expected a number from 1 to 60" in capsys.readouterr().err
    code = main(["plan-calibration", "--for", "identification", "--temperature-range", "5"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "--temperature-range applies to" in err


def test_the_plan_to_extend_is_never_the_physical_forms():
    def plan(form, n, rms):
        return PlanPrediction("grid", n, form, np.array(rms), np.array(rms), (form,), 0.0)

    floor = np.array([1.0, 1.0])
    study = PlanStudy([plan("physical", 49, [1.05, 1]), plan("auto", 196, [1.08, 1])], floor, 1, 0)
    assert plan_to_extend(study) == ("auto", "grid", 196)
    study = PlanStudy([plan("physical", 49, [1.05, 1]), plan("eq6", 196, [5, 5])], floor, 1, 0)
    assert plan_to_extend(study) == ("auto", "grid", 49)
    study = PlanStudy([plan("eq6", 100, [1.02, 1])], floor, 1, 0)
    assert plan_to_extend(study) == ("eq6", "grid", 100)
    assert plan_to_extend(study, within=0.01) is None


def test_the_allowed_thermometer_error_by_hand():
    # 1 K · √((1.5² − 1.1²) / (2.0² − 1.1²)) = √(1.04 / 2.79)
    assert allowed_error_k(1.1, 2.0) == pytest.approx(np.sqrt(1.04 / 2.79), rel=1e-12)
    assert allowed_error_k(1.1, 2.0, offset_k=0.5) == pytest.approx(0.5 * np.sqrt(1.04 / 2.79))
    assert allowed_error_k(1.6, 2.0) == 0.0  # the protocol's form alone is past the target
    assert allowed_error_k(1.1, 1.05) == np.inf  # an error that costs nothing


def test_the_thermometer_lines_say_the_figures_of_the_summary():
    rows = [
        {
            "imperfection": "thermometer 1 K off, in use only",
            "remedy": "logged",
            "ratio": 2.126,
            "protocol_ratio": 1.104,
        },
        {
            "imperfection": "all four at once, linear in ΔT",
            "remedy": "the whole protocol",
            "ratio": 3.61,
            "protocol_ratio": 1.6,
        },
    ]
    costs = {
        "changes_k": [-5.0, 5.0],
        "n_poses": 25,
        "curvature_per_k2": [-5e-5, -3.8e-5],
        "n_units": 2,
        "rows": rows,
        "protocol": {"lag_s": 5.0, "target": 1.5},
        "settle_rate_k_per_min": 0.671,
        "allowed_error_k": 0.5588,
    }
    text = "\n".join(thermometer_lines(costs))
    assert "25 poses at T0 -5 K and T0 +5 K" in text
    assert "curvature -5e-05/-3.8e-05 /K²" in text
    assert "thermometer 1 K off, in use only" + " " * 8 + "  2.13× → 1.10×  logged" in text
    assert "1.60× at worst, NOT within 1.5×" in text
    assert "less than 0.67 K/min" in text and "less than 0.56 K from calibration" in text
    assert thermometer_lines(None) == []


def test_the_command_gives_the_thermometer_costs_it_measured(temperature_plan):
    """plan.json's thermometer block: the five rows, the allowed error and the settling rate
    from its own rows by the stated formulas, and the printed lines with the same figures."""
    folder, printed = temperature_plan
    costs = json.loads((folder / "plan.json").read_text())["temperature"]["thermometer"]
    ratio = {row["case"]: (row["ratio"], row["protocol_ratio"]) for row in costs["rows"]}
    assert list(ratio) == list(COST_ROWS)
    expected = allowed_error_k(ratio["curvature"][1], ratio["thermometer_offset"][0])
    assert costs["allowed_error_k"] == pytest.approx(expected, rel=1e-12)
    assert costs["settle_rate_k_per_min"] == pytest.approx(0.1 * expected * 60 / 5.0)
    assert costs["changes_k"] == [-10.0, 10.0]
    assert f"{ratio['all'][0]:.2f}× → {ratio['all'][1]:.2f}×" in printed
    assert ratio["all"][0] > 2 * ratio["all"][1]  # the protocol is worth it on the default


def test_the_protocol_keeps_what_each_imperfection_costs_within_the_target():
    """On the sample optimised design (one unit, small plans): each imperfection alone, and all
    at once, takes the compensated error past 1.5× its white-noise error; compensated per the
    protocol, within it. The rows' 'without' are the protocol with its one remedy removed
    (the curvature term, the logged offset, the fast thermometer, the per-sensor readings)."""
    design = load_design(DATA / "design_6c47a9f.json")
    base = make_plan(design.workspace, "grid", 100)
    prediction = ThermalPrediction("both", 50, (-10.0, 10.0), np.zeros((5, 2)), np.zeros(2))
    study = thermometer_costs(design, base, prediction, form="poly4", n_units=1, n_validation=400)
    for name in ("curvature", "thermometer_offset", "strip_gradient", "all"):
        without, with_protocol = study.ratio[name]
        assert without > 1.5 and with_protocol <= 1.5, name
    assert study.ratio["thermometer_lag"][1] < study.ratio["thermometer_lag"][0]
    assert study.curvature_per_k2 == (-5e-5, -5e-5)  # the NJL5901R-2's assumed figure
