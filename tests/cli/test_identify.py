"""``reflector-opt identify``: AS_BUILT.json end to end, and bad input as one line, exit 2."""

import json

import numpy as np
import pytest

from reflector_opt.asbuilt._asbuiltfile import load_as_built
from reflector_opt.calibration._files import write_calibration_csv, write_csv, write_voltage_log
from reflector_opt.calibration._plans import make_plan
from reflector_opt.cli import main
from reflector_opt.design import Design, default_design
from reflector_opt.tolerance._builtunit import build_unit, built_unit_protocol


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """Calibration CSV of two built units, a voltage log, and one sensor's flat curve."""
    folder = tmp_path_factory.mktemp("identify")
    design = default_design()
    plan = make_plan(design.workspace, "sobol", 120, seed=0)
    labels, volts, angles, log_v, log_u, log_s = [], [], [], [], [], []
    units = []
    for index, label in enumerate(("A", "B")):
        unit = build_unit(design, index, seed=3)
        protocol = built_unit_protocol(unit, plan, n_validation=200, seed=index)
        labels += [label] * len(plan)
        volts.append(protocol.calibration.volts)
        angles.append(protocol.calibration.angles_deg)
        log_v.append(protocol.validation.volts)
        log_u += [label] * 200
        log_s += list(range(200))
        units.append((unit, protocol))
    write_calibration_csv(folder / "cal.csv", labels, np.vstack(volts), np.vstack(angles))
    order = np.argsort(np.array(log_s), kind="stable")
    write_voltage_log(
        folder / "log.csv",
        np.array(log_s)[order],
        np.array(log_u)[order],
        np.vstack(log_v)[order],
    )
    distance = np.linspace(0.5, 3.0, 11)
    curve = units[0][0].flat_curve(0, distance, np.random.default_rng(0))
    write_csv(folder / "s1.csv", ("distance_mm", "volts"), zip(distance, curve, strict=True))
    conditions = "[conditions]\nreference_zero_deg = [{}, {}]\nreference_twist_deg = 0.2\n"
    (folder / "cond.toml").write_text(conditions.format(-0.3, 0.0))
    (folder / "radians.toml").write_text(conditions.format(0.002, 0.001))
    return folder, units


@pytest.mark.slow
def test_identify_writes_an_as_built_file_that_the_other_commands_read(lab, tmp_path, capsys):
    folder, units = lab
    out = tmp_path / "AS_BUILT.json"
    argv = ["identify", str(folder / "cal.csv"), "--curve", f"A:S1={folder / 's1.csv'}"]
    assert main([*argv, "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "2 unit(s) identified" in printed and "unit A:" in printed
    assert printed.count("reference_pitch_zero_deg") == 2  # each unit's reference, fitted
    found = load_as_built(out)
    assert [u["unit"] for u in found.units] == ["A", "B"]
    assert [u["n_curves"] for u in found.units] == [1, 0]
    assert set(found.units[1]["reference"]["reference_twist_deg"]) >= {"std", "correlation"}
    row = found.units[0]["parameters"]["reflector_radius_mm"]
    assert set(row) >= {"estimate", "std", "prior_std", "identifiable", "interval_90"}
    # the as-built block is a design.json of its own
    design = Design.from_dict(found.document["units"][1]["as_built"])
    true_radius = units[1][0].design.reflector.radius_mm
    radius = found.units[1]["parameters"]["reflector_radius_mm"]
    assert abs(design.reflector.radius_mm - true_radius) < 3.3 * radius["std"]
    as_built = tmp_path / "unit_b.json"
    as_built.write_text(json.dumps(found.document["units"][1]["as_built"]))
    assert main(["evaluate", str(as_built), "--no-predict", "--json"]) == 0
    capsys.readouterr()
    angles = tmp_path / "angles.csv"
    assert main(["estimate", str(out), str(folder / "log.csv"), "-o", str(angles), "-q"]) == 0
    rows = np.genfromtxt(angles, delimiter=",", names=True, dtype=None, encoding="utf-8")
    assert len(rows) == 200


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--curve", "S1=s1.csv"], "the data hold 2 units; name the unit"),
        (["--curve", "C:S1=s1.csv"], "unit 'C' is not in the calibration data"),
        (["--curve", "A:S9=s1.csv"], "no sensor 'S9' in the design"),
        (["--curve", "A:S1"], "expected [UNIT:]SENSOR=FILE"),
        (["--curve", "A:S1=missing.csv"], "missing.csv"),
        (["--tolerances", "missing.toml"], "missing.toml"),
        (["--reference-sigma", "nan"], "--reference-sigma"),
        (["--reference-zero", "maybe"], "--reference-zero"),
        (["--reference-zero", "fixed", "--conditions", "cond.toml"], "give one of them"),
        (["--conditions", "missing.toml"], "missing.toml"),
        (["--conditions", "radians.toml"], "conditions.reference_zero_deg"),
    ],
)
def test_bad_input_is_one_line_and_nothing_is_written(
    lab, tmp_path, capsys, monkeypatch, extra, message
):
    folder, _ = lab
    monkeypatch.chdir(folder)
    out = tmp_path / "AS_BUILT.json"
    try:
        code = main(["identify", "cal.csv", *extra, "-o", str(out)])
    except SystemExit as exit_:  # a usage error, from argparse
        code = exit_.code
    assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err
    assert not out.exists()


def test_the_reference_prior_comes_from_the_conditions_or_is_fixed(lab, tmp_path, capsys):
    folder, _ = lab
    out = tmp_path / "AS_BUILT.json"
    argv = ["identify", str(folder / "cal.csv"), "--no-profiles", "-o", str(out)]
    assert main([*argv, "--conditions", str(folder / "cond.toml"), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    rows = summary["units"]["A"]["reference"]
    prior = {name: row["prior_std"] for name, row in rows.items()}
    assert prior == {
        "reference_pitch_zero_deg": 0.3,  # |−0.3|
        "reference_roll_zero_deg": 0.02,  # 0 floored
        "reference_twist_deg": 0.2,
    }
    assert load_as_built(out).document["prior"]["reference_std"] == prior
    assert main([*argv, "--reference-zero", "fixed"]) == 0
    text = capsys.readouterr().out
    assert "the angle reference was taken as exact" in text
    found = load_as_built(out)
    assert found.units[0]["reference"] is None and found.document["prior"]["reference_std"] is None


def test_units_with_too_few_samples_are_refused(tmp_path, capsys):
    data = tmp_path / "cal.csv"
    write_calibration_csv(data, ["1"] * 5, np.full((5, 2), 2.5), np.zeros((5, 2)))
    assert main(["identify", str(data), "-o", str(tmp_path / "a.json")]) == 2
    err = capsys.readouterr().err
    assert "unit 1: 5 samples give 10 voltages, fewer than" in err and err.count("\n") == 1
    assert not (tmp_path / "a.json").exists()


def test_a_file_that_is_not_as_built_is_named(tmp_path, capsys):
    path = tmp_path / "design.json"
    default_design().save(path)
    with pytest.raises(Exception, match="not an as-built file"):
        load_as_built(path)
