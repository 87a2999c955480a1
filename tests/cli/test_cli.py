"""The command line: output, machine-readable JSON, and one-line errors with exit code 2."""

import json

import numpy as np
import pytest

from reflector_opt.cli import main
from reflector_opt.design import default_design


def _hand_distance_range():
    """Eq 1–3 for the default design by hand: the sensors at f1 = (ρ, 0, 0) and f2 = (0, ρ, 0),
    the sphere centre s0 = (0, 0, z0) and s1 = Rx(α) Ry(γ) s0 = (z0 sin γ, −z0 cos γ sin α,
    z0 cos γ cos α) give |f1 − s1|² = ρ² + z0² − 2ρ z0 sin γ and
    |f2 − s1|² = ρ² + z0² + 2ρ z0 cos γ sin α; d = |f − s1| − r. Over the ±15° grid of 0.1°."""
    design = default_design()
    (rho, _, _), (_, rho_2, _) = design.positions_mm
    _, _, z0 = design.reflector.centre_mm
    assert rho == rho_2 and design.reflector.centre_mm[:2] == (0.0, 0.0)
    angles = np.deg2rad(np.linspace(-15.0, 15.0, 301))[:, None]
    gamma, alpha = angles, angles.T
    r = design.reflector.radius_mm
    d1 = np.sqrt(rho**2 + z0**2 - 2 * rho * z0 * np.sin(gamma)) - r
    d2 = np.sqrt(rho**2 + z0**2 + 2 * rho * z0 * np.cos(gamma) * np.sin(alpha)) - r
    return (d1.min(), d1.max()), (d2.min(), d2.max())


def test_evaluate_default_design(capsys):
    assert main(["evaluate", "--no-predict"]) == 0  # prediction: test_unit_calibration.py
    out = capsys.readouterr().out
    (low, high), _ = _hand_distance_range()
    assert f"S1 (NJL5901R-2): d {low:.3f}–{high:.3f} mm" in out
    assert "design stays inside the sensor range" in out


def test_evaluate_json(capsys, tmp_path):
    path = tmp_path / "design.json"
    default_design().save(path)
    assert main(["evaluate", str(path), "--json", "--no-predict"]) == 0
    summary = json.loads(capsys.readouterr().out)
    for sensor, (low, high) in zip(summary["sensors"], _hand_distance_range(), strict=True):
        assert sensor["distance_mm"]["min"] == pytest.approx(low, abs=1e-9)
        assert sensor["distance_mm"]["max"] == pytest.approx(high, abs=1e-9)
    assert summary["in_range"] is True
    assert summary["workspace"]["poses"] == 301**2


def _bad_design(tmp_path, mutate):
    data = default_design().to_dict()
    mutate(data)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    return str(path)


@pytest.mark.parametrize(
    ("mutate", "message"),
    [
        (
            lambda d: d["reflector"].update(radius_mm=0),
            "reflector.radius_mm: expected a number > 0 and ≤ 1000 mm, got 0",
        ),
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
    from reflector_opt.model._sensors import NJL5901R_2 as m

    d = np.linspace(0.3, 3.5, 20)
    v = m.with_(current_gain=2.0).output_voltage(m.flat_coupling(d, 0.9))
    curve = tmp_path / "curve.csv"
    curve.write_text(
        "distance_mm,volts\n" + "".join(f"{a},{b}\n" for a, b in zip(d, v, strict=True))
    )
    out = tmp_path / "measured.json"
    assert main(["fit-sensor", str(curve), "-o", str(out), "--method", "interpolate"]) == 0
    assert "gain 2" in capsys.readouterr().out
    assert main(["evaluate", str(out), "--json", "--no-predict"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["sensors"][0]["model"] == "NJL5901R-2-measured"


def test_fit_sensor_bad_csv_writes_nothing(tmp_path, capsys):
    curve = tmp_path / "curve.csv"
    curve.write_text("distance_mm,volts\n1,2\n2,oops\n")
    out = tmp_path / "measured.json"
    assert main(["fit-sensor", str(curve), "-o", str(out)]) == 2
    assert "row 3" in capsys.readouterr().err
    assert not out.exists()


def _material_curve(tmp_path, distance, reflectance=0.85, fraction=0.2):
    from reflector_opt.model._sensors import NJL5901R_2 as m

    noise = 0.002 * np.random.default_rng(0).standard_normal(distance.size)
    v = m.output_voltage(m.flat_coupling(distance, reflectance, fraction)) + noise
    curve = tmp_path / "sample.csv"
    curve.write_text(
        "distance_mm,volts\n" + "".join(f"{a},{b}\n" for a, b in zip(distance, v, strict=True))
    )
    return str(curve)


def test_fit_sensor_material_prints_and_writes_the_reflector(tmp_path, capsys):
    from reflector_opt.design import load_design

    curve = _material_curve(tmp_path, np.linspace(0.3, 4.0, 20))
    out = tmp_path / "design.json"
    assert main(["fit-sensor", curve, "--material", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "material against NJL5901R-2: reflectance ρ = 0.8" in text
    assert "specular fraction f = 0." in text and "over 20 points (0 clamped" in text
    reflector = load_design(out).reflector
    assert reflector.reflectance == pytest.approx(0.85, abs=0.01)
    assert reflector.specular_fraction == pytest.approx(0.2, abs=0.05)
    assert main(["fit-sensor", curve, "--material", "--design", str(out), "--json"]) == 0
    fit = json.loads(capsys.readouterr().out)
    assert fit["specular_fraction"] == pytest.approx(reflector.specular_fraction)
    assert 0.0 < fit["specular_fraction_sigma"] < 0.03 and fit["points"] == 20
    assert fit["sensor"] == "NJL5901R-2" and fit["output"] is None


@pytest.mark.parametrize(
    ("extra", "distance", "message"),
    [
        (["--reflectance", "0.9"], np.linspace(0.3, 4.0, 20), "--reflectance describes"),
        ([], np.linspace(2.0, 4.0, 10), "specular fraction is not determined"),
    ],
)
def test_fit_sensor_material_refusals_are_one_line(tmp_path, capsys, extra, distance, message):
    out = tmp_path / "design.json"
    curve = _material_curve(tmp_path, distance)
    assert main(["fit-sensor", curve, "--material", "-o", str(out), *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not out.exists()


def test_fit_sensor_material_bad_csv_exit_2(tmp_path, capsys):
    curve = tmp_path / "sample.csv"
    curve.write_text("distance_mm,volts\n0.5,1.0\n1.0,1.5\n2.0,inf\n3.0,3.0\n")
    assert main(["fit-sensor", str(curve), "--material"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("reflector-opt fit-sensor: error:") and "row 4" in err
    assert err.count("\n") == 1


def test_fit_sensor_needs_an_output_without_material(tmp_path, capsys):
    curve = _material_curve(tmp_path, np.linspace(0.3, 4.0, 8))
    assert main(["fit-sensor", curve]) == 2
    assert "-o/--out is required" in capsys.readouterr().err
