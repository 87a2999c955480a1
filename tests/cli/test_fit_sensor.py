"""``fit-sensor``: the reference target by name, the material fitted jointly with a reference
curve on the sample data, the misfit refusal, and the options that do not go together."""

import json
from pathlib import Path

import pytest

from reflector_opt.cli import build_parser, main
from reflector_opt.design import load_design
from reflector_opt.model._catalogue_fit import TARGETS

SAMPLE = Path(__file__).parents[2] / "examples" / "data"
S1, WHITE, MIRROR = (str(SAMPLE / n) for n in ("s1.csv", "white.csv", "mirror.csv"))
#: What unit 1's coupon was made of (examples/data/truth.json).
TRUTH = json.loads((SAMPLE / "truth.json").read_text())["units"][0]


def _one_line(capsys, fragment):
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and fragment in err, err


def test_the_material_against_the_white_card_holds_the_coupons_reflectance(tmp_path, capsys):
    out = tmp_path / "measured.json"
    argv = ["fit-sensor", S1, "--material", "--reference", WHITE, "--target", "white-card"]
    assert main([*argv, "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "material against NJL5901R-2 (fitted with it on " in text
    assert "reflectance 0.9, specular fraction 0)" in text and "sub-surface spread ℓ = " in text
    assert "90 % intervals (statistical and LED-pattern model form" in text
    design = load_design(out)
    assert abs(design.reflector.reflectance - TRUTH["reflectance"]) < 0.03
    assert {s.model for s in design.sensors} == {"NJL5901R-2-measured"}  # fitted with it
    assert main([*argv, "--json"]) == 0
    fit = json.loads(capsys.readouterr().out)
    low, high = fit["reflectance_interval"]
    assert low <= TRUTH["reflectance"] <= high and 0.0 <= low and high <= 1.0
    assert fit["reflectance"] == pytest.approx(design.reflector.reflectance)
    assert fit["sensor"] == "NJL5901R-2" and fit["misfit"] is False and fit["output"] is None


def test_the_material_against_the_mirror_is_refused_unless_accepted(tmp_path, capsys):
    out = tmp_path / "measured.json"
    argv = ["fit-sensor", S1, "--material", "--reference", MIRROR]
    argv += ["--reflectance", "0.87", "--specular-fraction", "1", "-o", str(out)]  # bare Al
    assert main(argv) == 2
    _one_line(capsys, "material curve: the model does not describe the readings")
    assert not out.exists()
    assert main([*argv, "--accept-misfit"]) == 0
    assert "warning: a curve's residual exceeds 3x the noise" in capsys.readouterr().out
    assert out.exists()


def test_a_sensor_fit_takes_the_target_by_name_and_reports_the_offset(tmp_path, capsys):
    out = tmp_path / "white.json"
    assert main(["fit-sensor", WHITE, "--target", "white-card", "-o", str(out)]) == 0
    captured = capsys.readouterr()
    # +6.9 mV: unit 1's S1 gain 1.013 on the output (+44 mV), its offset (−19 mV), stray light
    assert "output offset +6" in captured.out
    assert captured.err == ""  # residuals at the noise: no warning
    by_values = tmp_path / "values.json"
    argv = ["fit-sensor", WHITE, "--reflectance", "0.9", "--specular-fraction", "0"]
    assert main([*argv, "-o", str(by_values), "-q"]) == 0
    assert load_design(by_values).sensor_models == load_design(out).sensor_models


def test_a_sensor_fit_far_from_its_curve_warns_in_one_line(tmp_path, capsys):
    curve = tmp_path / "curve.csv"  # a line, not a sensor's curve
    curve.write_text(
        "distance_mm,volts\n"
        + "".join(f"{0.4 * i},{2.6 - 0.2 * i}\n" for i in (1, 2, 3, 4, 5, 6, 7, 8))
    )
    assert main(["fit-sensor", str(curve), "-o", str(tmp_path / "d.json"), "-q"]) == 0
    _one_line(capsys, "warning: residual RMS")


@pytest.mark.parametrize(
    ("extra", "fragment"),
    [
        (["--target", "grey-card"], "--target 'grey-card': unknown; known: white-card"),
        (["--target", "white-card", "--reflectance", "0.9"], "not both"),
        (["--material", "--reference", WHITE], "--reference: name its target"),
        (["--material", "--reference", WHITE, "--reflectance", "0.9"], "name its target"),
        (["--reference", WHITE], "--reference applies to --material only"),
        (["--accept-misfit"], "--accept-misfit applies to --material only"),
        (["--material", "--target", "white-card"], "--target describes the reference target"),
        (["--material", "--method", "fit"], "--method describes a sensor fit"),
    ],
)
def test_options_that_do_not_go_together_are_refused_in_one_line(tmp_path, capsys, extra, fragment):
    out = tmp_path / "design.json"
    assert main(["fit-sensor", S1, *extra, "-o", str(out)]) == 2
    _one_line(capsys, fragment)
    assert not out.exists()


def test_the_help_names_every_catalogue_target():
    (action,) = (a for a in build_parser()._actions if isinstance(a.choices, dict))
    text = action.choices["fit-sensor"].format_help()
    assert all(name in " ".join(text.split()) for name in TARGETS)
