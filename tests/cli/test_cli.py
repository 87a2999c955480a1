"""The command line: output, machine-readable JSON, and one-line errors with exit code 2."""

import json

import numpy as np
import pytest

from reflector_opt.cli import main
from reflector_opt.design import default_design


def test_evaluate_default_design(capsys):
    assert main(["evaluate"]) == 0
    out = capsys.readouterr().out
    assert "S1 (NJL5901R-2): d 0.720–1.489 mm" in out
    assert "design stays inside the sensor range" in out


def test_evaluate_json(capsys, tmp_path):
    path = tmp_path / "design.json"
    default_design().save(path)
    assert main(["evaluate", str(path), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    s1, s2 = summary["sensors"]
    assert s1["distance_mm"]["min"] == pytest.approx(0.7204, abs=1e-4)
    assert s1["distance_mm"]["max"] == pytest.approx(1.4888, abs=1e-4)
    assert s2["distance_mm"] == pytest.approx(s1["distance_mm"])
    assert summary["in_range"] is True
    assert summary["workspace"]["poses"] == 90601


def _bad_design(tmp_path, mutate):
    data = default_design().to_dict()
    mutate(data)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    return str(path)


@pytest.mark.parametrize(
    ("mutate", "message"),
    [
        (lambda d: d["reflector"].update(radius_mm=0), "reflector.radius_mm: must be positive"),
        (lambda d: d["sensors"][0].update(position_mm=[8, 0, 0]), "inside the reflector sphere"),
        (lambda d: d["reflector"].update(centre_mm=[0, "x", 0]), "centre_mm[1]: expected a number"),
        (lambda d: d.pop("workspace"), "workspace: missing key"),
        (lambda d: d["sensors"][0].update(model="NJL9999"), "unknown sensor preset 'NJL9999'"),
    ],
)
def test_bad_design_is_one_line_and_exit_2(tmp_path, capsys, mutate, message):
    assert main(["evaluate", _bad_design(tmp_path, mutate)]) == 2
    err = capsys.readouterr().err
    assert message in err
    assert err.count("\n") == 1 and "Traceback" not in err


def test_nan_in_json_is_rejected(tmp_path, capsys):
    path = tmp_path / "nan.json"
    path.write_text(json.dumps(default_design().to_dict()).replace("9.0", "NaN", 1))
    assert main(["evaluate", str(path)]) == 2
    assert "must be finite" in capsys.readouterr().err


def test_usage_errors_exit_2(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["evaluate", "--no-such-flag"])
    assert exc.value.code == 2
    with pytest.raises(SystemExit) as exc:
        main([])
    assert exc.value.code == 2


def test_fit_sensor_writes_a_design_that_evaluates(tmp_path, capsys):
    from reflector_opt.model.sensors import NJL5901R_2 as m

    d = np.linspace(0.3, 3.5, 20)
    v = m.with_(current_gain=2.0).output_voltage(m.flat_coupling(d, 0.9))
    curve = tmp_path / "curve.csv"
    curve.write_text(
        "distance_mm,volts\n" + "".join(f"{a},{b}\n" for a, b in zip(d, v, strict=True))
    )
    out = tmp_path / "measured.json"
    assert main(["fit-sensor", str(curve), "-o", str(out), "--method", "interpolate"]) == 0
    assert "gain 2" in capsys.readouterr().out
    assert main(["evaluate", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["sensors"][0]["model"] == "NJL5901R-2-measured"


def test_fit_sensor_bad_csv_writes_nothing(tmp_path, capsys):
    curve = tmp_path / "curve.csv"
    curve.write_text("distance_mm,volts\n1,2\n2,oops\n")
    out = tmp_path / "measured.json"
    assert main(["fit-sensor", str(curve), "-o", str(out)]) == 2
    assert "row 3" in capsys.readouterr().err
    assert not out.exists()
