"""The accuracy of ``estimate`` on the sample log that docs/calibration.md quotes is what the
documented commands give (issue 37, item 9), and the sample log's truth is the motion."""

import importlib.util
import re
from pathlib import Path

import numpy as np
import pytest

from reflector_opt.calibration._files import read_voltage_log
from reflector_opt.cli import main

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "examples" / "data"


def _script():
    spec = importlib.util.spec_from_file_location(
        "estimate_accuracy", ROOT / "examples" / "estimate_accuracy.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _quoted():
    """The figures of the block after ``<!-- estimate-accuracy -->`` in docs/calibration.md."""
    text = (ROOT / "docs" / "calibration.md").read_text()
    block = text.split("<!-- estimate-accuracy -->", 1)[1].split("```", 2)[1]
    found = re.findall(r"  ([a-z ]+): RMS ([\d.]+)(?:°| mm), max ([\d.]+)", block)
    return {name.replace(" ", "_"): (float(rms), float(peak)) for name, rms, peak in found}


def test_the_truth_is_the_papers_pitch_motion_by_hand():
    """Sample k: each of the 4 units at 15° · sin(2πk/50) in pitch, roll 0; the tip at four
    times that, 72 mm up the chain of 18 mm links at rest."""
    truth = _script()._table(DATA / "log_truth.csv")
    k = np.arange(50)
    for unit in "1234":
        np.testing.assert_allclose(
            truth[f"{unit}_pitch_deg"], 15 * np.sin(2 * np.pi * k / 50), atol=1e-4
        )
        assert not truth[f"{unit}_roll_deg"].any()
    np.testing.assert_allclose(truth["tip_pitch_deg"], 4 * truth["1_pitch_deg"], atol=2e-4)
    assert truth["tip_z_mm"][0] == 72.0
    log = read_voltage_log(DATA / "log.csv")
    assert [int(i) for i in log.instants] == truth["sample"].astype(int).tolist()


@pytest.fixture(scope="module")
def angles(tmp_path_factory):
    folder = tmp_path_factory.mktemp("estimate")
    coefficients, out = folder / "coefficients.json", folder / "angles.csv"
    argv = ["calibrate", str(DATA / "data.csv"), "--model", "auto", "-o", str(coefficients)]
    assert main([*argv, "-q"]) == 0
    assert main(["estimate", str(coefficients), str(DATA / "log.csv"), "-o", str(out), "-q"]) == 0
    return out


def test_the_quoted_accuracy_is_what_the_commands_give(angles):
    quoted = _quoted()
    assert set(quoted) == {"units", "tip_angles", "tip_position"}
    found = _script().accuracy(angles)
    assert found["samples"] == 50
    for name, (rms, peak) in quoted.items():
        assert found[name]["rms"] == pytest.approx(rms, abs=2e-3), name
        assert found[name]["max"] == pytest.approx(peak, abs=2e-3), name


def test_the_accuracy_is_measured_against_the_truth_not_the_estimate(angles, tmp_path):
    """The same table against itself has no error; against a truth moved by 0.1° in every
    angle, the unit RMS is 0.1° (a hand value), whatever the estimate."""
    script = _script()
    assert script.accuracy(DATA / "log_truth.csv")["units"]["rms"] == 0.0
    text = (DATA / "log_truth.csv").read_text().splitlines()
    header = text[0].split(",")
    moved = [text[0]]
    for line in text[1:]:
        cells = line.split(",")
        moved.append(
            ",".join(
                repr(float(c) + 0.1) if h.endswith("_deg") and h[0].isdigit() else c
                for h, c in zip(header, cells, strict=True)
            )
        )
    shifted = tmp_path / "shifted.csv"
    shifted.write_text("\n".join(moved) + "\n")
    assert script.accuracy(DATA / "log_truth.csv", shifted)["units"]["rms"] == pytest.approx(0.1)
