"""Each long command reports progress as it works, off a terminal as plain lines, and -q
silences it: plan-calibration, tolerance and calibrate --model physical, the three that ran
for tens of seconds without a word."""

import functools
import json
import logging
import re
import sys

import numpy as np
import pytest

import reflector_opt.cli._output as output
from reflector_opt.calibration._files import write_calibration_csv
from reflector_opt.calibration._physical import PhysicalModel
from reflector_opt.calibration._plans import make_plan
from reflector_opt.calibration._simulation import measure_with_design_noise
from reflector_opt.cli import main
from reflector_opt.util._progress import Progress


@pytest.fixture
def every_call_logged(monkeypatch):
    """Progress as off a terminal, but logging every call at once (no delay, no interval).

    The lines are written as a command that drew no bar writes them: without tqdm loaded
    (an earlier test in the same process may have drawn one), and with logging enabled and
    the package's loggers at their defaults, whatever earlier tests left."""
    monkeypatch.setattr(
        output, "Progress", functools.partial(Progress, terminal=False, interval_s=0, delay_s=0)
    )
    monkeypatch.delitem(sys.modules, "tqdm", raising=False)
    logging.disable(logging.NOTSET)
    for name in ("reflector_opt", "reflector_opt.util._progress"):
        logger = logging.getLogger(name)
        monkeypatch.setattr(logger, "disabled", False)
        monkeypatch.setattr(logger, "level", logging.NOTSET)
        logger.manager._clear_cache()


def _plan_calibration(tmp_path, design):
    design.save(tmp_path / "design.json")
    return ["plan-calibration", str(tmp_path / "design.json"), "--forms", "eq6,auto"]
    # two plans of one pattern, one unit: a second or two


def _tolerance(tmp_path, design):
    design.save(tmp_path / "design.json")
    (tmp_path / "quick.toml").write_text(
        "[settings]\ncalibration_step_deg = 2.0\nn_validation = 300\nmetrics_step_deg = 2.0\n"
        "[run]\nsamples = 4\noat_samples = 0\nsobol_samples = 0\nbatch_size = 2\nworkers = 1\n"
    )
    return [
        "tolerance",
        str(tmp_path / "design.json"),
        "--tolerances",
        str(tmp_path / "quick.toml"),
    ]


def _calibrate_physical(tmp_path, design):
    plan = make_plan(design.workspace, "sobol", 30, seed=2)
    model = PhysicalModel(design)
    clean = model._volts(model.nominal, plan[:, 0], plan[:, 1])
    volts = measure_with_design_noise(design, clean, np.random.default_rng(4))
    write_calibration_csv(tmp_path / "data.csv", ["a"] * 30, volts, plan)
    design.save(tmp_path / "design.json")
    return [
        "calibrate",
        str(tmp_path / "data.csv"),
        "--model",
        "physical",
        "--folds",
        "2",
        "--design",
        str(tmp_path / "design.json"),
    ]


COMMANDS = {
    "plan-calibration": (_plan_calibration, ["--patterns", "grid", "--sizes", "25,100"]),
    "tolerance": (_tolerance, []),
    "calibrate --model physical": (_calibrate_physical, []),
}


#: A progress line on stderr: "HH:MM:SS  NN% what (T s)".
PROGRESS_LINE = re.compile(r"^\d\d:\d\d:\d\d +\d{1,3}% .+ \(\d+ s\)$")


@pytest.mark.parametrize("name", list(COMMANDS))
def test_a_long_command_reports_progress_and_quiet_silences_it(
    name, design, tmp_path, capsys, every_call_logged
):
    make_argv, extra = COMMANDS[name]
    argv = [*make_argv(tmp_path, design), *extra]
    if name == "plan-calibration":
        argv += ["--units", "1"]
    assert main([*argv, "-o", str(tmp_path / "out")]) == 0
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if PROGRESS_LINE.match(line)]
    assert len(lines) >= 2, err
    assert "\r" not in err  # off a terminal: lines, not a redrawn bar
    assert main([*argv, "-q", "-o", str(tmp_path / "again")]) == 0
    assert not any(PROGRESS_LINE.match(line) for line in capsys.readouterr().err.splitlines())


def test_plan_calibration_json_is_the_summary_and_the_files(design, tmp_path, capsys):
    argv = _plan_calibration(tmp_path, design)
    argv += ["--patterns", "grid", "--sizes", "25,100", "--units", "1", "--within", "10"]
    argv += ["--json", "-q"]
    assert main([*argv, "-o", str(tmp_path / "out")]) == 0
    printed = json.loads(capsys.readouterr().out)
    written = json.loads((tmp_path / "out" / "plan.json").read_text())
    assert {k: printed[k] for k in written} == written
    assert printed["files"] == [
        str(tmp_path / "out" / n) for n in ("plan.csv", "plan.json", "plan.png")
    ]
    assert [p["n_poses"] for p in printed["predictions"]] == [25, 25, 100, 100]
    assert printed["recommended"]["n_poses"] == 25


def test_tolerance_json_is_the_study_summary_and_the_files(design, tmp_path, capsys):
    argv = [*_tolerance(tmp_path, design), "--json", "-q", "-o", str(tmp_path / "out")]
    assert main(argv) == 0
    printed = json.loads(capsys.readouterr().out)
    written = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert {k: printed[k] for k in written} == written
    assert printed["samples"] == 4 and printed["folder"] == str(tmp_path / "out")
    assert all(name.startswith(str(tmp_path / "out")) for name in printed["files"])
