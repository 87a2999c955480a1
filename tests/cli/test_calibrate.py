"""calibrate and estimate with a temperature_c column: the compensated form, and bad input."""

import json
from pathlib import Path

import numpy as np
import pytest

from reflector_opt.cli import main
from tests.calibration.thermal_data import write_thermal_lab

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "data"


@pytest.fixture(scope="module")
def lab(tmp_path_factory, design):
    """data.csv at 25 and 35 °C, log.csv at 30 °C, and the coefficients fitted to them."""
    folder = tmp_path_factory.mktemp("thermal")
    truth = write_thermal_lab(design, folder)
    assert (
        main(
            [
                "calibrate",
                str(folder / "data.csv"),
                "--model",
                "poly5",
                "-o",
                str(folder / "coef.json"),
                "-q",
            ]
        )
        == 0
    )
    return folder, truth


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_data_at_two_temperatures_give_the_compensated_form(lab, tmp_path, capsys):
    folder, _ = lab
    code, out, err = run(
        ["calibrate", folder / "data.csv", "--model", "poly5", "-o", tmp_path / "c.json"], capsys
    )
    assert code == 0, err
    assert "2 unit(s) calibrated with poly5 (lsq, temperature-compensated)" in out
    rows = [line.split() for line in out.splitlines() if line.strip().startswith(("1 ", "2 "))]
    thermal = [r for r in rows if "±" in r]
    assert len(thermal) == 2 and thermal[0][1] == "28.31" and thermal[0][2] == "25.0–35.0"
    units = json.loads((tmp_path / "c.json").read_text())["units"]
    for entry in units:
        block = entry["model"]["temperature"]
        assert entry["model"]["model"] == "poly5" and block["supply_v"] == [3.3, 3.3]
        assert all(0 < s < 1e-3 for s in block["gain_per_k_std"])
        assert all(-0.004 < c < -0.001 for c in block["gain_per_k"])  # the light path: −0.2 %/K


def test_the_json_summary_carries_the_thermal_parameters(lab, tmp_path, capsys):
    folder, _ = lab
    argv = ["calibrate", folder / "data.csv", "--model", "poly5", "--folds", "0", "--json"]
    code, out, _ = run([*argv, "-o", tmp_path / "c.json", "-q"], capsys)
    summary = json.loads(out)
    block = summary["units"]["2"]["temperature"]
    assert code == 0 and block["temperature_range_c"] == [25.0, 35.0]
    assert set(block) >= {"gain_per_k", "gain_per_k_std", "offset_v_per_k", "offset_v_per_k_std"}


def test_the_design_supplies_the_pivot(lab, design, tmp_path, capsys):
    from types import SimpleNamespace

    from reflector_opt.calibration._files import read_calibration_csv
    from reflector_opt.calibration._unit_calibration import calibrate_units

    folder, _ = lab
    samples = read_calibration_csv(folder / "data.csv")
    five_volts = SimpleNamespace(models=[SimpleNamespace(supply_v=5.0)] * 2)
    (unit, _) = calibrate_units(samples, "poly5", folds=0, design=five_volts)
    assert unit.model.supply_v_.tolist() == [5.0, 5.0]
    design.save(tmp_path / "design.json")
    argv = ["calibrate", folder / "data.csv", "--design", tmp_path / "design.json", "--folds", "0"]
    assert run([*argv, "--model", "poly5", "-o", tmp_path / "c.json"], capsys)[0] == 0
    block = json.loads((tmp_path / "c.json").read_text())["units"][0]["model"]["temperature"]
    assert block["supply_v"] == [m.supply_v for m in design.models]


def test_one_temperature_gives_the_plain_form(design, tmp_path, capsys):
    write_thermal_lab(design, tmp_path, temperatures=(25.0, 25.0))
    code, out, err = run(
        ["calibrate", tmp_path / "data.csv", "--folds", "0", "-o", tmp_path / "c.json"], capsys
    )
    assert code == 0, err
    assert "temperature-compensated" not in out and "±" not in out
    assert "temperature" not in json.loads((tmp_path / "c.json").read_text())["units"][0]["model"]
    log = tmp_path / "log.csv"  # a plain calibration leaves a log's temperatures alone
    assert run(["estimate", tmp_path / "c.json", log, "-o", tmp_path / "a.csv"], capsys)[0] == 0


def _angles(path):
    table = np.genfromtxt(path, delimiter=",", names=True)
    return np.stack(
        [np.column_stack([table[f"{u}_pitch_deg"], table[f"{u}_roll_deg"]]) for u in ("1", "2")],
        axis=1,
    )


def test_estimate_compensates_streamed_or_read_whole(lab, tmp_path, capsys):
    folder, truth = lab
    streamed, whole = tmp_path / "streamed.csv", tmp_path / "whole.csv"
    assert (
        run(["estimate", folder / "coef.json", folder / "log.csv", "-o", streamed], capsys)[0] == 0
    )
    lines = (folder / "log.csv").read_text().splitlines()
    shuffled = tmp_path / "shuffled.csv"  # rows of an instant apart: read whole
    shuffled.write_text("\n".join([lines[0], *lines[2::2], *lines[1::2]]) + "\n")
    assert run(["estimate", folder / "coef.json", shuffled, "-o", whole], capsys)[0] == 0
    assert np.array_equal(_angles(streamed), _angles(whole))
    error = np.sqrt(np.mean((_angles(streamed) - truth) ** 2, axis=0))
    assert np.all(error < 0.2), error  # about 0.1° of noise; 5 K uncompensated is ~3x that


def test_estimate_without_temperatures_is_refused_and_writes_nothing(lab, tmp_path, capsys):
    folder, _ = lab
    rows = [line.rsplit(",", 1)[0] for line in (folder / "log.csv").read_text().splitlines()]
    log, output = tmp_path / "log.csv", tmp_path / "angles.csv"
    log.write_text("\n".join(rows) + "\n")
    code, _, err = run(["estimate", folder / "coef.json", log, "-o", output], capsys)
    assert code == 2 and err.count("\n") == 1, err
    assert "no temperature_c column" in err and "coef.json" in err
    assert not output.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["log.csv"]


def _edited(text, line, column, value):
    """The CSV ``text`` with the cell of ``column`` on ``line`` (1-based) replaced."""
    rows = [r.split(",") for r in text.splitlines()]
    rows[line - 1][rows[0].index(column)] = value
    return "\n".join(",".join(r) for r in rows) + "\n"


@pytest.mark.parametrize(
    ("line", "value", "options", "message"),
    [
        (5, "nan", [], "line 5: column temperature_c is nan"),
        (7, "298.15", [], "line 7: column temperature_c: 298.15 looks like kelvin"),
        (9, "-80", [], "line 9: column temperature_c: -80 °C is below -60 °C"),
        (4, "", [], "line 4: column temperature_c is empty"),
        (None, None, [], "unit 2: temperature_c: the samples span 0 K"),
        (None, None, ["--model", "physical"], "temperature_c: --model physical is not"),
    ],
)
def test_bad_temperatures_in_calibration_data_exit_2(
    lab, tmp_path, capsys, line, value, options, message
):
    folder, _ = lab
    text = (folder / "data.csv").read_text()
    if line is not None:
        text = _edited(text, line, "temperature_c", value)
    elif not options:  # unit 2 recorded at one temperature only
        rows = text.splitlines()
        text = (
            "\n".join(
                [r if not r.startswith("2,") else r.rsplit(",", 1)[0] + ",25.0" for r in rows]
            )
            + "\n"
        )
    data, output = tmp_path / "data.csv", tmp_path / "c.json"
    data.write_text(text)
    code, _, err = run(["calibrate", data, *options, "-o", output], capsys)
    assert code == 2 and err.count("\n") == 1 and message in err, err
    assert not output.exists()


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ("inf", "line 6: column temperature_c is inf"),
        ("303.15", "line 6: column temperature_c: 303.15 looks like kelvin"),
    ],
)
def test_bad_temperatures_in_a_log_exit_2(lab, tmp_path, capsys, value, message):
    folder, _ = lab
    log, output = tmp_path / "log.csv", tmp_path / "angles.csv"
    log.write_text(_edited((folder / "log.csv").read_text(), 6, "temperature_c", value))
    code, _, err = run(["estimate", folder / "coef.json", log, "-o", output], capsys)
    assert code == 2 and err.count("\n") == 1 and message in err, err
    assert not output.exists()


def test_a_curved_compensation_from_three_temperatures_through_the_cli(design, tmp_path, capsys):
    """``--temperature-degree 2``: data at 15, 25 and 35 °C give each sensor's curvature with
    its standard deviation in the coefficients file, and the log at 30 °C is estimated
    within a tenth of a degree; two temperatures, or none, are refused naming what is wrong."""
    truth = write_thermal_lab(design, tmp_path, temperatures=(25.0, 15.0, 35.0))
    argv = ["calibrate", tmp_path / "data.csv", "--model", "poly5", "--folds", "0"]
    code, _, err = run([*argv, "--temperature-degree", "2", "-o", tmp_path / "c.json"], capsys)
    assert code == 0, err
    for entry in json.loads((tmp_path / "c.json").read_text())["units"]:
        block = entry["model"]["temperature"]
        assert len(block["gain_per_k2"]) == 2 and all(s > 0 for s in block["gain_per_k2_std"])
    angles = tmp_path / "angles.csv"
    code, _, err = run(
        ["estimate", tmp_path / "c.json", tmp_path / "log.csv", "-o", angles], capsys
    )
    assert code == 0, err
    error = np.sqrt(np.mean((_angles(angles) - truth) ** 2, axis=0))
    assert np.all(error < 0.2), error  # about 0.1° of noise, as the linear form's test
    two = tmp_path / "two"
    two.mkdir()
    write_thermal_lab(design, two)  # 25 and 35 °C only
    code, _, err = run(
        ["calibrate", two / "data.csv", "--temperature-degree", "2", "-o", two / "c.json"], capsys
    )
    assert code == 2 and "three temperatures" in err and not (two / "c.json").exists()
    plain = ["calibrate", EXAMPLES / "data.csv", "--temperature-degree", "2", "-o", two / "p.json"]
    code, _, err = run(plain, capsys)
    assert code == 2 and "--temperature-degree 2" in err and not (two / "p.json").exists()
