"""identify: the command's identification as one library call, with what it wrote and said."""

import json

import numpy as np
import pytest

from reflector_opt.asbuilt._asbuiltfile import load_as_built
from reflector_opt.calibration._files import write_calibration_csv
from reflector_opt.calibration._plans import make_plan
from reflector_opt.cli import main
from reflector_opt.tolerance._builtunit import build_unit, built_unit_protocol
from reflector_opt.util._errors import InputError
from reflector_opt.workflow import IdentifyRun, identify
from reflector_opt.workflow import _identify as workflow
from reflector_opt.workflow._identify import _form_lines

#: The fastest identification the command makes: no profiles, the reference taken as exact.
FAST = {"profiles": False, "reference_zero": "fixed"}


@pytest.fixture(scope="module")
def lab(tmp_path_factory, design):
    """One unit built by the tolerance model, its calibration on 40 Sobol poses."""
    folder = tmp_path_factory.mktemp("identify_run")
    unit = build_unit(design, 0, seed=3)
    plan = make_plan(design.workspace, "sobol", 40, seed=0)
    protocol = built_unit_protocol(unit, plan, n_validation=10, seed=0)
    calibration = protocol.calibration
    write_calibration_csv(
        folder / "cal.csv", ["U"] * len(plan), calibration.volts, calibration.angles_deg
    )
    return folder, unit


@pytest.fixture(scope="module")
def identified(lab, design):
    folder, _ = lab
    return identify(folder / "cal.csv", design=design, **FAST).write(folder / "AS_BUILT.json")


def test_the_run_writes_the_file_it_holds(identified):
    assert isinstance(identified, IdentifyRun)
    assert [p.name for p in identified.files] == ["AS_BUILT.json"]
    found = load_as_built(identified.files[0])
    assert [u["unit"] for u in found.units] == list(identified.result.labels) == ["U"]
    rows = identified.result.unit_parameters(0)
    for name, row in found.units[0]["parameters"].items():
        assert row["estimate"] == pytest.approx(rows[name]["estimate"], rel=1e-12), name


def test_the_radius_is_the_built_units_within_its_std(lab, identified):
    """Independent path: the unit's true radius, drawn by build_unit, which the
    identification never sees, within 3.3 std of the estimate."""
    _, unit = lab
    row = identified.result.unit_parameters(0)["reflector_radius_mm"]
    assert 0 < row["std"] < row["prior_std"]
    assert abs(row["estimate"] - unit.design.reflector.radius_mm) < 3.3 * row["std"]


def test_the_text_and_summary_say_the_same_deviations(identified):
    text = identified.text()
    lines = text.splitlines()
    assert lines[0].startswith("1 unit(s) identified in ")
    assert "unit U: deviation from the design (± std), determined ones" in lines
    assert lines[-1] == "the angle reference was taken as exact (--reference-zero fixed)"
    summary = identified.to_dict()
    assert set(summary) == {"shared", "units", "seconds"} and list(summary["units"]) == ["U"]
    assert summary["units"]["U"]["reference"] == {}
    for name, row in summary["units"]["U"]["determined"].items():
        assert f"    {name:<34}{row['deviation']:+10.4f} ± {row['std']:.4f}" in lines
    assert repr(identified) == text


def test_the_amplitudes_the_data_move_are_said():
    """Moved from their prior 0 by more than their std, or not said."""
    rows = {
        "form_cosine_power_sensor_1": {"estimate": 1.4, "std": 0.3},
        "form_two_gaussian_sensor_1": {"estimate": 0.2, "std": 0.9},
    }
    (line,) = _form_lines(rows)
    assert "cosine_power_sensor_1 +1.40 ± 0.30" in line and "two_gaussian" not in line
    assert _form_lines({"form_x_sensor_2": rows["form_two_gaussian_sensor_1"]}) == []


def test_the_command_prints_the_runs_text_and_summary(
    lab, identified, tmp_path, capsys, monkeypatch
):
    """The CLI parses, calls identify and prints its text, or its summary as JSON; the
    run it makes says what the library's run says, its time aside."""
    folder, _ = lab
    made = []

    def recording(*args, **kwargs):
        made.append(identify(*args, **kwargs))
        return made[-1]

    monkeypatch.setattr(workflow, "identify", recording)
    argv = ["identify", str(folder / "cal.csv"), "--no-profiles", "--reference-zero", "fixed"]
    assert main([*argv, "-o", str(tmp_path / "a.json"), "-q"]) == 0
    printed = capsys.readouterr().out
    assert printed.startswith(made[0].text() + "\nwrote 1 file in ")
    assert made[0].text().splitlines()[1:] == identified.text().splitlines()[1:]
    assert main([*argv, "-o", str(tmp_path / "b.json"), "--json"]) == 0
    expected = json.loads(json.dumps(made[1].to_dict()))
    assert json.loads(capsys.readouterr().out) == expected
    assert expected["units"] == json.loads(json.dumps(identified.to_dict()))["units"]


def test_the_reference_options_are_checked_before_any_work(lab, tmp_path):
    folder, _ = lab
    out = tmp_path / "x.json"
    with pytest.raises(InputError, match="give one of them"):
        identify(folder / "cal.csv", reference_zero="fixed", conditions="c.toml")
    with pytest.raises(
        InputError, match="--reference-zero: expected one of 'fixed', 'free', got 'loose'"
    ):
        identify(folder / "cal.csv", reference_zero="loose")
    with pytest.raises(InputError, match="batch: expected a name"):
        identify(folder / "cal.csv", batch=" b")
    assert not out.exists()


def test_voltages_beyond_the_supply_are_refused_unless_accepted(lab, design, tmp_path, capsys):
    """A bench whose read-out sits 0.9 V above the 3.3 V supply's range: one line, exit 2,
    nothing written; taken as given with --accept-units."""
    folder, _ = lab
    table = np.genfromtxt(folder / "cal.csv", delimiter=",", names=True, dtype=None)
    volts = np.column_stack([table["v1"], table["v2"]]) + 0.9
    assert volts.max() > 3.3 * 1.05
    angles = np.column_stack([table["pitch_deg"], table["roll_deg"]])
    data = tmp_path / "high.csv"
    write_calibration_csv(data, ["U"] * len(volts), volts, angles)
    out = tmp_path / "AS_BUILT.json"
    argv = ["identify", str(data), "--no-profiles", "--reference-zero", "fixed", "-o", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "beyond the 3.3 V supply" in err and "--accept-units" in err
    assert not out.exists()
    assert main([*argv, "--accept-units", "-q", "--json"]) == 0
    assert list(json.loads(capsys.readouterr().out)["units"]) == ["U"]
    assert load_as_built(out).units[0]["unit"] == "U"
