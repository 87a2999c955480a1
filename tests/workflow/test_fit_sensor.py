"""fit_sensor: the command's sensor and material fits in memory, written by the run's
``write``, with what they wrote and said, on the sample data (a white card and a coupon of
unit 1's material)."""

import json
from pathlib import Path

import pytest

from reflector_opt.cli import main
from reflector_opt.design import load_design
from reflector_opt.util._errors import InputError
from reflector_opt.workflow._fit_sensor import (
    DEFAULT_BASE,
    FitSensorRun,
    check_outputs,
    fit_sensor,
)

SAMPLE = Path(__file__).parents[2] / "examples" / "data"
S1, WHITE = str(SAMPLE / "s1.csv"), str(SAMPLE / "white.csv")
#: What unit 1's coupon was made of (examples/data/truth.json).
TRUTH = json.loads((SAMPLE / "truth.json").read_text())["units"][0]


@pytest.fixture(scope="module")
def sensor(tmp_path_factory):
    out = tmp_path_factory.mktemp("fit_sensor") / "measured.json"
    return fit_sensor(WHITE, target="white-card").write(str(out))


def test_the_sensor_fit_writes_the_design_with_its_model(sensor):
    assert isinstance(sensor, FitSensorRun) and not sensor.material
    design = load_design(sensor.output)
    assert {m.name for m in design.models} == {sensor.fit.model.name}
    assert sensor.fit.model.name.startswith(DEFAULT_BASE)
    assert sensor.points == 26 and sensor.files == (sensor.output,)
    assert sensor.to_dict()["points"] == 26 and sensor.to_dict()["output"] == sensor.output


def test_the_material_against_the_fitted_sensor_holds_the_coupons_truth(sensor):
    """Independent path: what the sample coupon was built as (truth.json), inside the 90 %
    intervals of the fit against the sensor fitted on the white card."""
    run = fit_sensor(S1, material=True, design=sensor.output)
    assert run.material and run.files == () and run.sensor.name == sensor.fit.model.name
    low, high = run.fit.reflectance_interval
    assert low <= TRUTH["reflectance"] <= high
    low, high = run.fit.specular_fraction_interval
    assert low <= TRUTH["specular_fraction"] <= high
    assert run.to_dict()["sensor"] == run.sensor.name and run.to_dict()["output"] is None
    assert run.text().splitlines()[0].startswith(f"material against {run.sensor.name}: ")


def test_options_that_do_not_apply_are_refused(tmp_path):
    fitted = fit_sensor(WHITE, reflectance=0.87)  # in memory: nothing asked of it yet
    with pytest.raises(InputError, match=r"^-o/--out is required \(unless --material\)$"):
        fitted.write()
    with pytest.raises(InputError, match=r"^--part-file: the target must be one of the catalog"):
        fitted.write(tmp_path / "d.json", part_file=tmp_path / "p.toml")  # no test target
    with pytest.raises(InputError, match=r"^--part-file: not with --material"):
        check_outputs(True, None, tmp_path / "p.toml")  # the command's check, and write's
    with pytest.raises(InputError, match=r"^--method describes a sensor fit"):
        fit_sensor(S1, material=True, method="fit")
    with pytest.raises(InputError, match=r"unknown sensor preset ''; known presets: "):
        fit_sensor(WHITE, base="")  # not taken for the default
    assert list(tmp_path.iterdir()) == []


def test_the_earlier_name_writes_as_before(tmp_path):
    with pytest.warns(DeprecationWarning, match="fit_sensor_run is deprecated"):
        from reflector_opt import workflow

        run = workflow.fit_sensor_run(WHITE, tmp_path / "d.json", target="white-card")
    assert run.files == (tmp_path / "d.json",) and (tmp_path / "d.json").is_file()


def test_the_command_prints_the_runs_text_and_summary(sensor, tmp_path, capsys):
    argv = ["fit-sensor", WHITE, "--target", "white-card", "-q"]
    assert main([*argv, "-o", str(tmp_path / "a.json")]) == 0
    assert capsys.readouterr().out.startswith(sensor.text() + "\nwrote 1 file in ")
    out = str(tmp_path / "b.json")
    assert main([*argv, "-o", out, "--json"]) == 0
    expected = json.loads(json.dumps({**sensor.to_dict(), "output": out}))
    assert json.loads(capsys.readouterr().out) == expected
