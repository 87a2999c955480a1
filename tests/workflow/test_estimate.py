"""estimate: the command's estimate as one library call, with what it wrote and said."""

import json

import numpy as np
import pytest

from reflector_opt.cli import main
from reflector_opt.design._components import Mechanics
from reflector_opt.workflow import EstimateRun, calibrate, estimate
from tests.calibration.thermal_data import write_thermal_lab


@pytest.fixture(scope="module")
def lab(tmp_path_factory, design):
    """The coefficients of two units fitted at 25 and 35 °C, a log at 30 °C and its truth."""
    folder = tmp_path_factory.mktemp("estimate_run")
    truth = write_thermal_lab(design, folder)
    calibrate(folder / "data.csv", model="poly5", folds=0).write(folder / "coef.json")
    return folder, truth


@pytest.fixture(scope="module")
def estimated(lab):
    folder, _ = lab
    return estimate(folder / "coef.json", folder / "log.csv").write(folder / "angles.csv")


def _columns(path):
    header = path.read_text().splitlines()[0].split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return {name: data[:, i] for i, name in enumerate(header)}


def test_the_run_writes_the_angles_of_the_log(lab, estimated):
    """Independent path: the log's true angles, within a quarter of a degree RMS."""
    _, truth = lab
    assert isinstance(estimated, EstimateRun)
    assert (estimated.instants, estimated.units, estimated.tip) == (60, ["1", "2"], True)
    angles = _columns(estimated.files[0])
    for j, unit in enumerate(estimated.units):
        got = np.column_stack([angles[f"{unit}_pitch_deg"], angles[f"{unit}_roll_deg"]])
        assert np.all(np.sqrt(np.mean((got - truth[:, j]) ** 2, axis=0)) < 0.25)


def test_the_link_length_scales_the_tip_position(lab, estimated, tmp_path):
    """The same angles with 20 mm links: the tip's position × 20 / 18 (the default link)."""
    folder, _ = lab
    longer = estimate(folder / "coef.json", folder / "log.csv", link_length_mm=20.0)
    longer = longer.write(tmp_path / "a.csv")
    base, scaled = _columns(estimated.files[0]), _columns(longer.files[0])
    ratio = 20.0 / Mechanics.link_length_mm
    assert Mechanics.link_length_mm == 18.0
    for axis in ("x", "y", "z"):
        np.testing.assert_allclose(scaled[f"tip_{axis}_mm"], ratio * base[f"tip_{axis}_mm"])


def test_the_command_prints_the_runs_text_and_summary(lab, estimated, tmp_path, capsys):
    folder, _ = lab
    argv = ["estimate", str(folder / "coef.json"), str(folder / "log.csv"), "-q"]
    assert main([*argv, "-o", str(tmp_path / "a.csv")]) == 0
    assert estimated.text() == "60 instant(s) × 2 unit(s) estimated (with tip angles and position)"
    assert capsys.readouterr().out.startswith(estimated.text() + "\nwrote 1 file in ")
    out = str(tmp_path / "b.csv")
    assert main([*argv, "-o", out, "--json"]) == 0
    expected = json.loads(json.dumps({**estimated.to_dict(), "output": out}))
    assert json.loads(capsys.readouterr().out) == expected
