"""Calibration from measured CSV data and estimation from voltage logs, via the library and CLI."""

import json
import os
import re

import numpy as np
import pytest
from numpy.testing import assert_allclose

import reflector_opt as ro
from reflector_opt.calibration._files import (
    read_calibration_csv,
    read_voltage_log,
    write_calibration_csv,
    write_voltage_log,
)
from reflector_opt.calibration._segment import tip_angles, tip_pose
from reflector_opt.calibration._synthetic import built_units, calibration_data, voltage_log
from reflector_opt.calibration._unit_calibration import (
    calibrate_csv,
    estimate_log,
    load_calibrations,
    save_calibrations,
)
from reflector_opt.cli import main
from reflector_opt.util._errors import InputError

HEADER = "unit,v1,v2,pitch_deg,roll_deg\n"


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """A simulated built segment: its calibration CSV, a pitch-motion log and the truth."""
    folder = tmp_path_factory.mktemp("lab")
    design = ro.default_design()
    units = built_units(design, seed=3)
    data = calibration_data(design, units, step_deg=1.0, seed=1)
    write_calibration_csv(folder / "data.csv", data["unit"], data["volts"], data["angles_deg"])
    log = voltage_log(design, units, "pitch", cycles=1, samples_per_cycle=40, seed=2)
    write_voltage_log(folder / "log.csv", log["sample"], log["unit"], log["volts"])
    return {"folder": folder, "data": data, "truth": log["angles_deg"]}


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


# --- round trip ----------------------------------------------------------------------------------


def test_calibrate_then_estimate_round_trip(lab, capsys):
    folder = lab["folder"]
    coef, angles = folder / "coef.json", folder / "angles.csv"
    code, out, err = run(
        ["calibrate", folder / "data.csv", "--model", "poly5", "--folds", "3", "-o", coef], capsys
    )
    assert code == 0, err
    assert "3-fold cross-validated error" in out and "wrote" in out
    assert re.search(r"^\s+1\s+961\s+0\.\d+°", out, re.MULTILINE)
    assert re.search(r"^\s+4\s+961\s+0\.\d+°", out, re.MULTILINE)
    stored = json.loads(coef.read_text())
    assert [u["unit"] for u in stored["units"]] == ["1", "2", "3", "4"]
    assert stored["units"][0]["model"]["model"] == "poly5"
    assert stored["units"][0]["cross_validation"]["folds"] == 3

    code, out, err = run(["estimate", coef, folder / "log.csv", "-o", angles], capsys)
    assert code == 0, err
    table = np.genfromtxt(angles, delimiter=",", names=True)
    truth = lab["truth"]  # (samples, units, 2)
    assert len(table) == truth.shape[0]
    for j in range(4):
        assert_allclose(table[f"{j + 1}_pitch_deg"], truth[:, j, 0], atol=0.5)
        assert_allclose(table[f"{j + 1}_roll_deg"], truth[:, j, 1], atol=0.5)
    rotation, position = tip_pose(truth[..., 0], truth[..., 1], 18.0)
    assert_allclose(table["tip_pitch_deg"], tip_angles(rotation)[:, 0], atol=1.5)
    assert_allclose(table["tip_x_mm"], position[:, 0], atol=1.5)
    assert np.abs(table["tip_pitch_deg"]).max() > 55  # the ±60° sweep


def test_library_calibration_matches_the_cli_file(lab, tmp_path):
    folder = lab["folder"]
    calibrations = calibrate_csv(folder / "data.csv", "eq6", "lsq", folds=0)
    assert all(c.cross_validation is None for c in calibrations)
    save_calibrations(tmp_path / "c.json", calibrations, source="data.csv")
    loaded = load_calibrations(tmp_path / "c.json")
    volts = lab["data"]["volts"][:100]
    for a, b in zip(calibrations, loaded, strict=True):
        assert a.unit == b.unit
        assert_allclose(b.model.predict(volts), a.model.predict(volts), atol=1e-10)
    shape = estimate_log(loaded[:2], _two_unit_log(tmp_path))
    assert shape.tip_angles_deg is not None and shape.units == ["1", "2"]
    partial = estimate_log(loaded, _two_unit_log(tmp_path))
    assert partial.tip_angles_deg is None and "tip_pitch_deg" not in partial.header()


def _two_unit_log(folder):
    path = folder / "two.csv"
    path.write_text("time,unit,v1,v2\n0.0,2,2.4,2.5\n0.0,1,2.5,2.4\n0.1,1,2.6,2.3\n0.1,2,2.3,2.6\n")
    return path


def test_log_grouping_by_time_and_by_order(tmp_path):
    log = read_voltage_log(_two_unit_log(tmp_path))
    assert log.key == "time" and log.instants == ["0.0", "0.1"] and log.units == ["2", "1"]
    assert_allclose(log.volts[0], [[2.4, 2.5], [2.5, 2.4]])
    path = tmp_path / "ordered.csv"
    path.write_text("unit,v1,v2\na,1,2\nb,3,4\na,5,6\nb,7,8\n")
    log = read_voltage_log(path, accept_units=True)  # readings beyond a 3.3 V supply
    assert log.key == "sample" and log.instants == ["0", "1"]
    assert_allclose(log.volts[:, 1], [[3, 4], [7, 8]])


def test_calibration_csv_reader_keeps_units_in_order(tmp_path):
    path = tmp_path / "d.csv"
    path.write_text(  # with the byte-order mark spreadsheet programs write
        "\ufeffroll_deg,pitch_deg,v2,v1,unit,note\n1,2,3,4,B,x\n5,6,7,8,A,y\n9,10,11,12,B,z\n",
        encoding="utf-8",
    )
    data = read_calibration_csv(path, accept_units=True)  # beyond a 3.3 V supply
    assert list(data) == ["B", "A"]
    assert_allclose(data["B"].volts, [[4, 3], [12, 11]])
    assert_allclose(data["B"].angles_deg, [[2, 1], [10, 9]])
    assert list(data["B"].lines) == [2, 4]


# --- bad input: exit 2, one line naming the problem, nothing written ------------------------------


def _rows(n, unit="1", pose=None):
    rng = np.random.default_rng(n)
    lines = []
    for _ in range(n):
        p, r = pose if pose else rng.uniform(-15, 15, 2)
        lines.append(f"{unit},{rng.uniform(1, 3):.4f},{rng.uniform(1, 3):.4f},{p:.3f},{r:.3f}\n")
    return "".join(lines)


CALIBRATE_CASES = {
    "missing column": ("unit,v1,v2,pitch_deg\n1,1,2,3\n", [], "missing column(s) roll_deg"),
    "non-numeric": (HEADER + _rows(20) + "1,2.0,abc,1,1\n", [], "line 22: column v2: 'abc'"),
    "nan row": (HEADER + _rows(5) + "1,nan,2.0,1,1\n" + _rows(20), [], "line 7: column v1 is nan"),
    "empty cell": (HEADER + _rows(3) + "1,2.0,,1,1\n", [], "line 5: column v2 is empty"),
    "short row": (HEADER + "1,2.0,1.0\n", [], "line 2: 3 cells"),
    "too few samples": (HEADER + _rows(30) + _rows(5, unit="2"), [], "unit 2: eq6 lsq fit: 5"),
    "single pose": (HEADER + _rows(30, pose=(3.0, 4.0)), [], "same pose"),
    "no data": (HEADER, [], "no data rows"),
    "empty file": ("", [], "empty file"),
    "unknown model": (HEADER + _rows(30), ["--model", "eq7"], "unknown model 'eq7'"),
    "unknown fit": (
        HEADER + _rows(30),
        ["--fit", "l1"],
        "--fit: expected one of 'huber', 'lsq', 'minimax', got 'l1'",
    ),
    "bad degree": (HEADER + _rows(30), ["--model", "poly12"], "degree"),
    "bad folds": (HEADER + _rows(30), ["--folds", "1"], "folds"),
    "rank deficient": (
        HEADER + "".join(f"1,2.0,{1 + i / 30:.4f},{i % 7},{i % 5}\n" for i in range(30)),
        [],
        "rank",
    ),
}


@pytest.mark.parametrize("case", CALIBRATE_CASES)
def test_calibrate_bad_input(case, tmp_path, capsys):
    text, options, message = CALIBRATE_CASES[case]
    data, output = tmp_path / "data.csv", tmp_path / "coef.json"
    data.write_text(text)
    code, _, err = run(["calibrate", data, *options, "-o", output], capsys)
    assert code == 2
    assert message in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not output.exists()
    assert list(tmp_path.iterdir()) == [data]  # no temporary file left either


def test_calibrate_missing_file(tmp_path, capsys):
    code, _, err = run(["calibrate", tmp_path / "nope.csv", "-o", tmp_path / "c.json"], capsys)
    assert code == 2 and "cannot read" in err


@pytest.fixture(scope="module")
def coefficients(lab):
    path = lab["folder"] / "eq6.json"
    save_calibrations(path, calibrate_csv(lab["folder"] / "data.csv", "eq6", folds=0))
    return path


ESTIMATE_CASES = {
    "unknown unit": ("sample,unit,v1,v2\n0,9,2.4,2.5\n", "unit(s) 9 have no calibration"),
    "missing column": ("sample,unit,v1\n0,1,2.4\n", "missing column(s) v2"),
    "non-numeric": ("sample,unit,v1,v2\n0,1,2.4,x\n", "line 2: column v2: 'x'"),
    "duplicate": ("sample,unit,v1,v2\n0,1,2.4,2.5\n0,1,2.4,2.5\n", "line 3: a second row"),
    "gap": ("sample,unit,v1,v2\n0,1,2.4,2.5\n0,2,2.4,2.5\n1,1,2.4,2.5\n", "sample 1 has no row"),
    "unequal": ("unit,v1,v2\n1,2.4,2.5\n1,2.4,2.5\n2,2.4,2.5\n", "different numbers of rows"),
}


@pytest.mark.parametrize("case", ESTIMATE_CASES)
def test_estimate_bad_log(case, coefficients, tmp_path, capsys):
    text, message = ESTIMATE_CASES[case]
    log, output = tmp_path / "log.csv", tmp_path / "angles.csv"
    log.write_text(text)
    code, _, err = run(["estimate", coefficients, log, "-o", output], capsys)
    assert code == 2 and message in err
    assert len(err.strip().splitlines()) == 1
    assert not output.exists()


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("{", "not valid JSON"),
        ('{"format": "x"}', "not a calibration file"),
        ('{"format": "reflector-opt/calibration@1", "units": []}', "non-empty list"),
        (
            '{"format": "reflector-opt/calibration@1", "units": [{"unit": "1", "model": {}}]}',
            "model.model: missing key",
        ),
    ],
)
def test_estimate_bad_coefficients(content, message, lab, tmp_path, capsys):
    coef = tmp_path / "coef.json"
    coef.write_text(content)
    code, _, err = run(
        ["estimate", coef, lab["folder"] / "log.csv", "-o", tmp_path / "a.csv"], capsys
    )
    assert code == 2 and message in err


def _misspelled(data, key):
    data["units"][0]["cross_validation"] = {
        "folds": 5,
        "rms_deg": {"pitch_deg": 0.5, "roll_deg": 0.5},
        "max_deg": {"pitch_deg": 1.0, "roll_deg": 1.0},
    }
    return {
        "top": lambda: data.update(sorce="lab"),
        "unit": lambda: data["units"][0].update(notes="x"),
        "cross_validation": lambda: data["units"][0]["cross_validation"].update(fold=5),
        "rms_deg": lambda: data["units"][0]["cross_validation"]["rms_deg"].update(yaw_deg=1),
    }[key]()


@pytest.mark.parametrize(
    ("key", "message"),
    [
        ("top", ": unknown key(s) sorce; allowed: format, source, units"),
        ("unit", ": units[0]: unknown key(s) notes; allowed: unit, cross_validation, model"),
        ("cross_validation", ": units[0].cross_validation: unknown key(s) fold; allowed: folds"),
        ("rms_deg", ": units[0].cross_validation.rms_deg: unknown key(s) yaw_deg; allowed: pitch"),
    ],
)
def test_a_key_the_calibration_file_does_not_have_is_refused(coefficients, tmp_path, key, message):
    """A misspelt key was read as if it were not there (estimate exited 0)."""
    data = json.loads(coefficients.read_text())
    _misspelled(data, key)
    path = tmp_path / "coef.json"
    path.write_text(json.dumps(data))
    with pytest.raises(InputError, match=f"^{re.escape(str(path) + message)}"):
        load_calibrations(path)


def test_library_errors_name_the_problem(tmp_path):
    path = tmp_path / "d.csv"
    path.write_text("unit,unit,v1,v2,pitch_deg,roll_deg\n")
    with pytest.raises(InputError, match="duplicate column"):
        read_calibration_csv(path)
    with pytest.raises(InputError, match="link_length_mm"):
        estimate_log([], path, link_length_mm=0.0)


# --- evaluate ------------------------------------------------------------------------------------


def test_evaluate_json_has_the_predicted_blocks(capsys):
    code, out, _ = run(["evaluate", "--json"], capsys)
    assert code == 0
    summary = json.loads(out)
    assert summary["in_range"] is True and len(summary["sensors"]) == 2  # existing keys kept
    eq6 = summary["calibration"]["eq6"]
    for key in ("rms_deg", "max_deg"):
        assert 0 < eq6[key]["pitch"] < 5 and 0 < eq6[key]["roll"] < 5
    assert eq6["rms_deg"]["pitch"] < summary["calibration"]["eq5"]["rms_deg"]["pitch"]
    assert summary["calibration"]["protocol"]["n_calibration"] == 90601
    segment = summary["segment"]
    assert segment["pitch"]["paper"]["rms_deg"] == 2.45
    assert segment["roll"]["predicted"]["max_deg"] > segment["roll"]["predicted"]["rms_deg"]


def test_evaluate_text_and_no_predict(capsys):
    code, out, _ = run(["evaluate"], capsys)
    assert code == 0 and "predicted calibration" in out and "Table I" in out
    code, out, _ = run(["evaluate", "--json", "--no-predict"], capsys)
    assert code == 0 and "calibration" not in json.loads(out)


def test_calibrate_auto_writes_the_chosen_form_per_unit(lab, capsys):
    folder = lab["folder"]
    coef = folder / "auto.json"
    argv = ["calibrate", folder / "data.csv", "--model", "auto", "--folds", "3", "-o", coef]
    code, out, err = run(argv, capsys)
    assert code == 0, err
    stored = json.loads(coef.read_text())
    chosen = {u["model"]["model"] for u in stored["units"]}
    # forward-model data with small noise: a high-order polynomial, never Eq 5 or Eq 6
    assert chosen and all(re.fullmatch(r"poly[4-8]", name) for name in chosen)
    assert f"calibrated with {'/'.join(sorted(chosen))}" in out


@pytest.mark.skipif(not os.path.isdir("/dev/fd"), reason="opens a pipe by its /dev/fd name")
def test_a_log_from_a_pipe_is_estimated_as_from_its_file(lab, coefficients, tmp_path):
    """estimate COEF <(cat log.csv) said 'empty file': the stream read the pipe's header,
    then opened it again, empty."""
    from reflector_opt.calibration._unit_calibration import estimate_to_csv

    log = lab["folder"] / "log.csv"
    data = log.read_bytes()
    assert len(data) < 60_000  # fits the pipe's buffer: written whole before it is read
    read, write = os.pipe()
    try:
        os.write(write, data)
        os.close(write)
        calibrations = load_calibrations(coefficients)
        piped = estimate_to_csv(calibrations, f"/dev/fd/{read}", tmp_path / "piped.csv")
    finally:
        os.close(read)
    direct = estimate_to_csv(calibrations, log, tmp_path / "direct.csv")
    assert piped == direct and piped["instants"] > 0
    assert (tmp_path / "piped.csv").read_bytes() == (tmp_path / "direct.csv").read_bytes()
