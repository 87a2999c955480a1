"""Calibration planning: predictions against a direct simulation of the plan, recommendation."""

import json

import numpy as np
import pytest

from reflector_opt.calibration._files import write_calibration_csv
from reflector_opt.calibration._plans import make_plan
from reflector_opt.calibration._unit_calibration import calibrate_csv
from reflector_opt.cli import main
from reflector_opt.tolerance._builtunit import build_unit
from reflector_opt.tolerance._planning import PlanPrediction, PlanStudy, motion_time_s, recommend
from reflector_opt.util._errors import InputError


def test_prediction_matches_a_direct_simulation_of_the_written_plan(design, tmp_path, capsys):
    design.save(tmp_path / "design.json")
    out = tmp_path / "plan"
    argv = ["plan-calibration", str(tmp_path / "design.json"), "--forms", "auto"]
    argv += ["--patterns", "grid", "--sizes", "100", "--units", "2", "--within", "10"]
    assert main([*argv, "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "recommended: auto on a 100-pose grid" in printed
    summary = json.loads((out / "plan.json").read_text())
    predicted = summary["recommended"]["rms_deg"]
    assert (out / "plan.png").stat().st_size > 10_000

    # the plan as a rig would run it: read the CSV, record each unit with fresh noise,
    # calibrate through the lab workflow, validate at fresh poses
    plan = np.genfromtxt(out / "plan.csv", delimiter=",", names=True)
    poses = np.column_stack([plan["pitch_deg"], plan["roll_deg"]])
    assert len(poses) == 100
    rng = np.random.default_rng(2024)
    rms = []
    for index in range(2):
        unit = build_unit(design, index, seed=0)
        data = unit.record(poses, rng)
        path = tmp_path / f"unit{index}.csv"
        write_calibration_csv(path, ["u"] * len(poses), data.volts, data.angles_deg)
        (fitted,) = calibrate_csv(path, "auto", folds=0)
        truth = rng.uniform(-15, 15, (4000, 2))
        check = unit.record(truth, rng, 0.0)
        error = fitted.model.predict(check.volts) - truth
        rms.append(np.sqrt(np.mean(error**2, axis=0)))
    direct = np.sqrt(np.mean(np.square(rms), axis=0))
    assert direct == pytest.approx([predicted["pitch"], predicted["roll"]], rel=0.12)


def _prediction(n, rms):
    return PlanPrediction("grid", n, "auto", np.array(rms), np.array(rms) * 4, ("poly4",), 0.0)


def test_recommend_takes_the_smallest_plan_within_the_margin():
    study = PlanStudy(
        [_prediction(400, [1.02, 1.0]), _prediction(100, [1.09, 1.05]), _prediction(50, [1.3, 1])],
        np.array([1.0, 1.0]),
        1,
        0,
    )
    assert recommend(study).n_poses == 100
    assert recommend(study, within=0.05).n_poses == 400
    assert recommend(study, within=0.01) is None


def test_motion_time_is_path_over_speed_plus_dwell(design):
    plan = make_plan(design.workspace, "grid", 4)  # a 30° + 30° + 30° serpentine
    assert motion_time_s(plan, 10.0, 0.5) == pytest.approx(9.0 + 2.0)
    assert motion_time_s(90.0, 10.0, 0.5, n_poses=4) == pytest.approx(11.0)
    with pytest.raises(InputError, match="speed"):
        motion_time_s(plan, 0.0)


def test_bad_arguments_are_one_line(design, tmp_path, capsys):
    design.save(tmp_path / "design.json")
    for extra in (["--sizes", "2"], ["--speed", "0"]):
        assert main(["plan-calibration", str(tmp_path / "design.json"), *extra]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and extra[0] in err[0]
    out = tmp_path / "none"
    argv = ["plan-calibration", str(tmp_path / "design.json"), "--patterns", "zigzag"]
    code = main([*argv, "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "zigzag" in err[0]
    assert not out.exists()


def test_a_design_without_signal_is_refused_before_anything_is_written(design, tmp_path, capsys):
    """A reflectance of 1e-300 (or a sensor 999 mm away) gave an infinite Cramér–Rao floor,
    and plan-calibration ended in an internal error writing it to plan.json."""
    import dataclasses

    dark = design.replace(reflector=dataclasses.replace(design.reflector, reflectance=1e-300))
    dark.save(tmp_path / "design.json")
    out = tmp_path / "plan"
    argv = ["plan-calibration", str(tmp_path / "design.json"), "--sizes", "25", "--units", "1"]
    code = main([*argv, "--forms", "eq6", "--patterns", "grid", "--out", str(out), "-q"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert "the design's voltages do not determine the pose" in err and "floor is infinite" in err
    assert not out.exists()
