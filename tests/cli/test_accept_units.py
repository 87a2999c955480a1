"""Input files in the wrong unit are refused by every command that reads them, in one line
with exit code 2 and nothing written, unless --accept-units (issue 37, item 2).

Issue 37 found: radians in pitch_deg/roll_deg made calibrate exit 0 with an RMS of 0.004°;
distances in metres to fit-sensor exited 0 with a residual of 1.23 V and a file written.
"""

import csv
from pathlib import Path

import pytest

from reflector_opt.cli import main

SAMPLES = Path(__file__).parents[2] / "examples" / "data"


def _rescaled(source, target, scale):
    """``source`` CSV with the named columns multiplied by their factors."""
    with open(source, newline="") as handle:
        rows = list(csv.DictReader(handle))
    with open(target, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        for row in rows:
            writer.writerow(
                {k: repr(float(v) * scale[k]) if k in scale else v for k, v in row.items()}
            )
    return str(target)


def _refused(argv, capsys, fragment, written):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and fragment in err and "--accept-units" in err, err
    assert not Path(written).exists()


def test_calibrate_refuses_radians(tmp_path, capsys):
    rad = 3.141592653589793 / 180
    data = _rescaled(
        SAMPLES / "data.csv", tmp_path / "rad.csv", {"pitch_deg": rad, "roll_deg": rad}
    )
    out = tmp_path / "c.json"
    _refused(["calibrate", data, "-o", str(out)], capsys, "they look like radians", out)
    assert main(["calibrate", data, "-o", str(out), "--accept-units", "--folds", "0"]) == 0


def test_calibrate_refuses_millivolts(tmp_path, capsys):
    data = _rescaled(SAMPLES / "data.csv", tmp_path / "mv.csv", {"v1": 1e3, "v2": 1e3})
    out = tmp_path / "c.json"
    _refused(
        ["calibrate", data, "-o", str(out)],
        capsys,
        "v1 spans 1383.32–2844.8, beyond the 3.3 V supply: that looks like millivolts",
        out,
    )


@pytest.mark.parametrize(
    ("scale", "fragment"),
    [
        ({"distance_mm": 1e-3}, "column distance_mm spans 0.0003–0.004: that looks like metres"),
        ({"distance_mm": 1e3}, "that looks like micrometres"),
        (
            {"volts": 1e3},
            "column volts spans 815.332–3204.13, beyond the 3.3 V supply: that looks like "
            "millivolts",
        ),
    ],
)
def test_fit_sensor_refuses_a_curve_in_another_unit(tmp_path, capsys, scale, fragment):
    curve = _rescaled(SAMPLES / "mirror.csv", tmp_path / "curve.csv", scale)
    out = tmp_path / "fitted.json"
    argv = [
        "fit-sensor",
        curve,
        "--reflectance",
        "0.87",
        "--specular-fraction",
        "1",
        "-o",
        str(out),
    ]
    _refused(argv, capsys, fragment, out)


def test_fit_sensor_material_and_its_reference_are_checked(tmp_path, capsys):
    metres = _rescaled(SAMPLES / "white.csv", tmp_path / "white_m.csv", {"distance_mm": 1e-3})
    out = tmp_path / "fitted.json"
    argv = ["fit-sensor", str(SAMPLES / "white.csv"), "--material", "--reference", metres]
    argv += ["--target", "white-card", "-o", str(out)]
    _refused(argv, capsys, "white_m.csv: column distance_mm", out)


def test_fit_sensor_accepts_when_told(tmp_path, capsys):
    curve = _rescaled(SAMPLES / "mirror.csv", tmp_path / "curve.csv", {"distance_mm": 1e-3})
    out = tmp_path / "fitted.json"
    argv = ["fit-sensor", curve, "--reflectance", "0.87", "--specular-fraction", "1"]
    assert main([*argv, "-o", str(out), "--accept-units", "-q"]) == 0 and out.exists()


def test_estimate_refuses_a_log_in_millivolts(tmp_path, capsys):
    coefficients = tmp_path / "c.json"
    assert (
        main(["calibrate", str(SAMPLES / "data.csv"), "-o", str(coefficients), "--folds", "0"]) == 0
    )
    log = _rescaled(SAMPLES / "log.csv", tmp_path / "log_mv.csv", {"v1": 1e3, "v2": 1e3})
    out = tmp_path / "angles.csv"
    _refused(["estimate", str(coefficients), log, "-o", str(out)], capsys, "millivolts", out)


def test_estimate_refuses_a_reading_beyond_the_supply_in_a_streamed_log(tmp_path, capsys):
    """An ordered log is read in blocks; a 5 V bench's log is refused there too."""
    coefficients = tmp_path / "c.json"
    assert (
        main(["calibrate", str(SAMPLES / "data.csv"), "-o", str(coefficients), "--folds", "0"]) == 0
    )
    log = _rescaled(SAMPLES / "log.csv", tmp_path / "log_5v.csv", {"v1": 5 / 3.3, "v2": 5 / 3.3})
    out = tmp_path / "angles.csv"
    _refused(
        ["estimate", str(coefficients), log, "-o", str(out)], capsys, "beyond the 3.3 V supply", out
    )


def test_the_sample_data_pass_every_check(tmp_path):
    """The sample data are volts of a 3.3 V supply, millimetres and degrees."""
    from reflector_opt.calibration._files import read_calibration_csv, read_voltage_log
    from reflector_opt.model._measured import read_curve_csv

    read_calibration_csv(SAMPLES / "data.csv")
    read_voltage_log(SAMPLES / "log.csv")
    for name in ("s1.csv", "s2.csv", "mirror.csv", "white.csv"):
        read_curve_csv(SAMPLES / name)
