"""tolerance: the command's study as one library call, with what it wrote and said."""

import csv
import json

import numpy as np
import pytest

from reflector_opt.cli import main
from reflector_opt.workflow import ToleranceRun, tolerance
from reflector_opt.workflow._tolerance import tolerance_config

#: A quick study: coarse calibration and validation, no sensitivity, one worker.
QUICK = (
    "[settings]\ncalibration_step_deg = 2.0\nn_validation = 300\nmetrics_step_deg = 2.0\n"
    "[run]\nsamples = 4\noat_samples = 0\nsobol_samples = 0\nbatch_size = 2\nworkers = 1\n"
)


@pytest.fixture(scope="module")
def files(tmp_path_factory, design):
    folder = tmp_path_factory.mktemp("tolerance_run")
    design.save(folder / "design.json")
    (folder / "quick.toml").write_text(QUICK)
    return folder


@pytest.fixture(scope="module")
def studied(files):
    return tolerance(
        files / "design.json", tolerances=files / "quick.toml", samples=6, seed=3
    ).write(files / "out")


def test_the_overrides_replace_the_files_samples_and_seed(files):
    config = tolerance_config(files / "quick.toml", samples=6, seed=3)
    assert (config.run.samples, config.run.seed, config.run.batch_size) == (6, 3, 2)
    assert tolerance_config(files / "quick.toml").run.samples == 4


def test_the_yield_is_the_share_of_written_units_within_the_targets(studied):
    """By hand from samples.csv: the units whose window is kept and whose errors are within
    the targets; the 95 % Wilson interval of 6 of 6 is 6 / (6 + 1.96²) to 1."""
    assert isinstance(studied, ToleranceRun)
    assert [f.name for f in studied.files] == [
        "samples.csv",
        "summary.json",
        "yield.png",
        "errors.png",
    ]
    with studied.files[0].open() as handle:
        rows = list(csv.DictReader(handle))
    targets = studied.study.summary["targets"]
    good = [
        r["window_kept"] == "True"
        and max(float(r["rms_pitch_deg"]), float(r["rms_roll_deg"])) <= targets["rms_deg"]
        and max(float(r["max_pitch_deg"]), float(r["max_roll_deg"])) <= targets["max_deg"]
        for r in rows
    ]
    assert len(rows) == 6 and studied.study.summary["yield"]["all"] == sum(good) / 6
    median = np.median([float(r["rms_pitch_deg"]) for r in rows])
    assert f"RMS pitch error (°): median {median:.3f}," in studied.text()
    if all(good):
        assert "(95 % interval 61.0–100.0 %;" in studied.text()  # 6 / 9.8415 = 0.6097


def test_the_command_prints_the_runs_text_and_summary(files, studied, tmp_path, capsys):
    argv = ["tolerance", str(files / "design.json"), "--tolerances", str(files / "quick.toml")]
    argv += ["--samples", "6", "--seed", "3", "-q", "-o"]
    assert main([*argv, str(tmp_path / "a")]) == 0
    assert capsys.readouterr().out.startswith(studied.text() + "\nwrote 5 files in ")
    assert main([*argv, str(tmp_path / "b"), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    expected = json.loads(json.dumps(studied.to_dict(), default=float))
    assert printed.pop("folder") == str(tmp_path / "b") and expected.pop("folder")
    assert printed.pop("files") == [str(tmp_path / "b" / f.name) for f in studied.files]
    expected.pop("files")
    assert printed == expected
