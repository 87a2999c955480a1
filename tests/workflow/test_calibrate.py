"""calibrate: the command's calibration as one library call, with what it wrote and said."""

import json

import numpy as np
import pytest

from reflector_opt.calibration._unit_calibration import load_calibrations
from reflector_opt.cli import main
from reflector_opt.workflow import CalibrateRun, calibrate
from tests.calibration.thermal_data import write_thermal_lab


@pytest.fixture(scope="module")
def lab(tmp_path_factory, design):
    """data.csv at 25 and 35 °C and log.csv at 30 °C of two units, with the log's truth."""
    folder = tmp_path_factory.mktemp("calibrate_run")
    return folder, write_thermal_lab(design, folder)


@pytest.fixture(scope="module")
def calibrated(lab):
    folder, _ = lab
    return calibrate(folder / "data.csv", model="poly5", folds=2).write(folder / "coef.json")


def test_the_run_writes_the_coefficients_it_holds(calibrated):
    assert isinstance(calibrated, CalibrateRun)
    assert [p.name for p in calibrated.files] == ["coef.json"]
    read = load_calibrations(calibrated.files[0])
    assert [c.unit for c in read] == [c.unit for c in calibrated.calibrations] == ["1", "2"]
    for a, b in zip(read, calibrated.calibrations, strict=True):
        assert a.to_dict() == b.to_dict()


def test_the_calibration_recovers_the_logs_angles(lab, calibrated):
    """Independent path: the log's true angles (the fast model's voltages at 30 °C, with the
    design's noise), which calibrate never sees, within a quarter of a degree RMS."""
    folder, truth = lab
    log = np.loadtxt(folder / "log.csv", delimiter=",", skiprows=1, usecols=(2, 3))
    for j, c in enumerate(calibrated.calibrations):
        volts = log[j :: len(calibrated.calibrations)]
        angles = c.model.predict(volts, temperature_c=np.full(len(volts), 30.0))
        rms = np.sqrt(np.mean((angles - truth[:, j]) ** 2, axis=0))
        assert np.all(rms < 0.25), rms


def test_the_text_and_summary_name_the_compensated_form(calibrated):
    text = calibrated.text()
    assert text.splitlines()[0] == "2 unit(s) calibrated with poly5 (lsq, temperature-compensated)"
    assert "2-fold cross-validated error" in text and "temperature compensation" in text
    summary = calibrated.to_dict()
    assert summary["folds"] == 2 and set(summary["units"]) == {"1", "2"}
    assert summary["units"]["1"]["samples"] == 81 + 40
    assert "gain_per_k" in summary["units"]["2"]["temperature"]


def test_the_command_prints_the_runs_text_and_summary(lab, calibrated, tmp_path, capsys):
    """The CLI parses, calls calibrate and prints its text, or its summary as JSON."""
    folder, _ = lab
    argv = ["calibrate", str(folder / "data.csv"), "--model", "poly5", "--folds", "2", "-q"]
    assert main([*argv, "-o", str(tmp_path / "a.json")]) == 0
    assert capsys.readouterr().out.startswith(calibrated.text() + "\nwrote 1 file in ")
    out = str(tmp_path / "b.json")
    assert main([*argv, "-o", out, "--json"]) == 0
    expected = json.loads(json.dumps({**calibrated.to_dict(), "output": out}))
    assert json.loads(capsys.readouterr().out) == expected
