"""The plan for identification end to end: the command writes the D-optimal plan and the
table, with and without a check, and refuses what it cannot plan in one line."""

import json

import numpy as np
import pytest

from reflector_opt.cli import main


def test_cli_writes_the_d_optimal_plan_and_the_table(design, tmp_path, capsys):
    design.save(tmp_path / "design.json")
    out = tmp_path / "plan"
    argv = ["plan-calibration", str(tmp_path / "design.json"), "--for", "identification"]
    argv += ["--patterns", "d-optimal,grid", "--sizes", "25", "--units", "1"]
    argv += ["--candidate-step", "3", "--forms", "physical", "--out", str(out)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "recommended:" in printed and "D-optimal poses" in printed
    assert "physical" in printed and "identification" in printed
    summary = json.loads((out / "plan.json").read_text())
    best = summary["recommended"]
    plan = np.genfromtxt(out / "plan.csv", delimiter=",", names=True)
    assert plan.dtype.names == ("pose", "pitch_deg", "roll_deg")
    poses = np.column_stack([plan["pitch_deg"], plan["roll_deg"]])
    assert len(np.unique(poses, axis=0)) == len(poses) == best["n_poses"]
    assert np.all(np.abs(poses) <= 15.0)
    assert [p["pattern"] for p in summary["patterns"]] == ["d-optimal", "grid"]
    assert summary["patterns"][0]["log_det"] > summary["patterns"][1]["log_det"]
    assert summary["calibration"]["predictions"][0]["form"] == "physical"


def test_cli_fisher_only_plan_without_a_check(design, tmp_path, capsys):
    out = tmp_path / "plan"
    argv = ["plan-calibration", "--for", "identification", "--no-check", "--sizes", "25,50"]
    argv += ["--patterns", "d-optimal,sobol", "--candidate-step", "2", "--target-std", "0.45"]
    assert main([*argv, "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "target: posterior std ≤ 0.45 × prior std" in printed
    summary = json.loads((out / "plan.json").read_text())
    assert summary["n_units"] == 0 and summary["calibration"] is None
    assert all(row["check"] is None for row in summary["patterns"])
    assert [(r["pattern"], r["n_poses"]) for r in summary["patterns"]] == [
        ("d-optimal", 25),
        ("d-optimal", 50),
        ("sobol", 25),
        ("sobol", 50),
    ]
    plan = np.genfromtxt(out / "plan.csv", delimiter=",", names=True)
    assert len(plan) == summary["recommended"]["n_poses"]
    assert set(summary["recommended"]["determinable"]) == {
        p["name"] for p in summary["parameters"] if p["ratio_all_candidates"] <= 0.45
    }


@pytest.mark.parametrize(
    ("extra", "fragment"),
    [
        (["--for", "identification", "--target-std", "1.5"], "--target-std"),
        (["--target-std", "0.5"], "--target-std applies to --for identification only"),
        (["--truth", "model"], "--truth applies to --for identification only"),
        (["--for", "identification", "--patterns", "raster"], "raster cannot be planned"),
        (["--for", "identification", "--sizes", "8"], "8 poses are too few"),
        (["--for", "identification", "--sizes", "2000"], "exceed the 961 candidates"),
        (["--for", "identification", "--truth", "model", "--forms", "auto"], "--forms"),
        (["--for", "testing"], "--for"),
        (["--for", "identification", "--candidate-step", "0.3"], "more than 4,000"),
    ],
)
def test_bad_input_is_one_line(design, tmp_path, capsys, extra, fragment):
    design.save(tmp_path / "design.json")
    out = tmp_path / "plan"
    argv = ["plan-calibration", str(tmp_path / "design.json"), *extra, "--out", str(out)]
    try:
        code = main(argv)
    except SystemExit as exit_info:
        code = exit_info.code
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and fragment in err[0]
    assert not out.exists()
