"""``--json``: the summary a command prints, as strict JSON that agrees with what it wrote."""

import csv
import json
import math

import numpy as np
import pytest

from reflector_opt.cli import main
from reflector_opt.cli._output import print_json


def _strict(text):
    """Parse JSON, refusing the NaN and Infinity that Python's json would accept."""

    def refuse(constant):
        raise AssertionError(f"non-standard JSON constant {constant}")

    return json.loads(text, parse_constant=refuse)


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    from tests.labfiles import write_lab_files

    folder = tmp_path_factory.mktemp("lab")
    write_lab_files(folder)
    return folder


def test_print_json_writes_numpy_and_non_finite_as_standard_json(capsys):
    print_json({"a": np.float64(1.5), "b": np.array([1, 2]), "c": math.nan, "d": (np.inf,)})
    assert _strict(capsys.readouterr().out) == {"a": 1.5, "b": [1, 2], "c": None, "d": [None]}


def test_calibrate_json_is_the_cross_validation_it_wrote(lab, tmp_path, capsys):
    out = tmp_path / "coefficients.json"
    argv = ["calibrate", str(lab / "data.csv"), "--folds", "3", "-o", str(out), "--json"]
    assert main(argv) == 0
    printed = _strict(capsys.readouterr().out)
    written = json.loads(out.read_text())
    units = {u["unit"]: u for u in written["units"]}
    assert set(printed["units"]) == set(units) and len(units) == 2
    for name, row in printed["units"].items():
        assert row["cross_validation"] == units[name]["cross_validation"]
        assert all(0 < v < 1 for v in row["cross_validation"]["rms_deg"].values())  # degrees
    assert printed["output"] == str(out) and printed["folds"] == 3


def test_estimate_json_counts_the_rows_it_wrote(lab, tmp_path, capsys):
    out = tmp_path / "angles.csv"
    argv = ["estimate", str(lab / "coef.json"), str(lab / "log.csv"), "-o", str(out), "--json"]
    assert main(argv) == 0
    printed = _strict(capsys.readouterr().out)
    with open(out, newline="") as f:
        rows = list(csv.DictReader(f))
    with open(lab / "log.csv", newline="") as f:
        instants = {r["sample"] for r in csv.DictReader(f)}
    assert printed["instants"] == len(instants) > 0
    assert len(rows) == printed["instants"] and len(printed["units"]) == 2


def test_sweep_json_is_the_table_it_wrote(tmp_path, capsys):
    from reflector_opt.design import default_design

    design = tmp_path / "design.json"
    default_design().save(design)
    out = tmp_path / "sweep"
    argv = ["sweep", str(design), "--vary", "reflector.radius_mm=8,9", "-o", str(out), "--json"]
    assert main(argv) == 0
    printed = _strict(capsys.readouterr().out)
    with open(out / "sweep.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [p["reflector.radius_mm"] for p in printed["points"]] == [8.0, 9.0]
    for point, row in zip(printed["points"], rows, strict=True):
        assert point["status"] == row["status"] == "ok"
        assert point["nominal_rms_pitch_deg"] == pytest.approx(float(row["nominal_rms_pitch_deg"]))
    assert printed["files"] == ["sweep.csv", "sweep.png"]


def test_every_command_prints_its_json_through_print_json():
    """A command that called json.dumps itself printed NaN, which strict readers refuse."""
    from pathlib import Path

    import reflector_opt.cli

    folder = Path(reflector_opt.cli.__file__).parent
    direct = [p.name for p in folder.glob("*.py") if "json.dumps(" in p.read_text()]
    assert direct == ["_output.py"], direct
