"""plan_calibration: the command's plan as one library call, with what it wrote and said."""

import json
from itertools import product

import numpy as np
import pytest

from reflector_opt.calibration._files import read_plan_csv
from reflector_opt.cli import main
from reflector_opt.util._errors import InputError
from reflector_opt.workflow import PlanCalibrationRun, plan_calibration

#: A small calibration plan: a 5 × 5 grid against one built unit, recommended within 10×.
SMALL = {"forms": ("eq6",), "patterns": ("grid",), "sizes": (25,), "units": 1, "within": 10.0}


@pytest.fixture(scope="module")
def planned(tmp_path_factory):
    return plan_calibration(None, **SMALL).write(tmp_path_factory.mktemp("plan") / "plan")


def test_the_recommended_grid_is_written_as_plan_csv(planned):
    """By hand: the default workspace's ±15° box on a 5 × 5 grid, row by row, every other
    row reversed; its path 6 rows' worth of 7.5° steps (24 steps, 180°) at 10°/s plus 0.5 s
    at each of the 25 poses."""
    assert isinstance(planned, PlanCalibrationRun)
    assert [f.name for f in planned.files] == ["plan.csv", "plan.json", "plan.png"]
    poses, changes = read_plan_csv(planned.out / "plan.csv")
    steps = np.linspace(-15.0, 15.0, 5)
    assert changes is None and sorted(map(tuple, poses)) == sorted(product(steps, steps))
    assert poses[:6].tolist() == [[-15.0, r] for r in steps] + [[-7.5, 15.0]]
    best = planned.summary["recommended"]
    assert (best["pattern"], best["n_poses"]) == ("grid", 25)
    assert best["motion_time_s"] == pytest.approx(24 * 7.5 / 10.0 + 25 * 0.5)
    assert json.loads((planned.out / "plan.json").read_text()) == json.loads(
        json.dumps(planned.summary)
    )


def test_the_text_names_the_recommendation(planned):
    lines = planned.text().splitlines()
    assert lines[0].startswith("predicted calibration error over 1 built units (seed 0)")
    assert lines[-1].startswith("recommended: eq6 on a 25-pose grid (")
    summary = planned.to_dict()
    assert summary["folder"] == str(planned.out)
    assert summary["files"] == [str(f) for f in planned.files]


def test_options_of_the_other_purpose_are_refused_before_any_work(tmp_path):
    with pytest.raises(InputError, match=r"^--target-std applies to --for identification only$"):
        plan_calibration(None, target_std=0.5)
    with pytest.raises(InputError, match=r"^--temperature-range applies to --for calibration"):
        plan_calibration(None, purpose="identification", temperature_range_k=5)
    assert list(tmp_path.iterdir()) == []


def test_a_plan_for_identification_without_the_check(tmp_path):
    run = plan_calibration(None, purpose="identification", sizes=(25,), check=False)
    run = run.write(tmp_path / "id")
    assert [f.name for f in run.files] == ["plan.csv", "plan.json"]
    poses, _ = read_plan_csv(run.files[0])
    assert np.array_equal(poses, run.study.plan.poses_deg)
    assert run.text().startswith("plan for identification: ")


def test_the_command_prints_the_runs_text_and_summary(planned, tmp_path, capsys):
    argv = ["plan-calibration", "--forms", "eq6", "--patterns", "grid", "--sizes", "25"]
    argv += ["--units", "1", "--within", "10", "-q"]
    assert main([*argv, "-o", str(tmp_path / "a")]) == 0
    assert capsys.readouterr().out.startswith(planned.text() + "\nwrote 4 files in ")
    out = tmp_path / "b"
    assert main([*argv, "-o", str(out), "--json"]) == 0
    expected = {**planned.to_dict(), "folder": str(out)}
    expected["files"] = [str(out / f.name) for f in planned.files]
    assert json.loads(capsys.readouterr().out) == json.loads(json.dumps(expected))
