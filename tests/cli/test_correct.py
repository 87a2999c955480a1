"""``reflector-opt correct``: end to end on a small batch, and its one-line refusals."""

import copy
import json
import re

import pytest

from reflector_opt.asbuilt._asbuiltfile import identification_to_dict
from reflector_opt.asbuilt._model_form_terms import EXACT, OPTICAL_EFFECTS
from reflector_opt.cli import main
from reflector_opt.design import default_design, load_design
from tests.asbuilt.printloop import CORRECTED_SEED, drawn_design, printed


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """AS_BUILT.json of a 4-unit batch (B1) that ``correct`` corrects, its design, and
    variants of the file."""
    folder = tmp_path_factory.mktemp("printloop")
    _, result = printed("strong", seed=CORRECTED_SEED)
    document = identification_to_dict(result, "cal.csv", batch="B1")
    drawn_design().save(folder / "design.json")
    files = {"batch": document}
    files["two_units"] = {**copy.deepcopy(document), "units": document["units"][:2]}
    other = copy.deepcopy(document)
    other["batch"] = "B2"
    for unit in other["units"]:
        unit["unit"] = f"b{unit['unit']}"
    files["other_batch"] = other
    deep = copy.deepcopy(document)  # every seat of sensor 1 1.5 mm deeper than it can be
    for unit in deep["units"]:
        unit["parameters"]["sensor_1_standoff_mm"]["estimate"] += 1.5
    files["deep_seats"] = deep
    for name, data in files.items():
        (folder / f"{name}.json").write_text(json.dumps(data))
    return folder


def _run(capsys, *argv):
    code = main(["correct", *map(str, argv)])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.slow
def test_correct_writes_the_corrected_design_and_parts(lab, capsys):
    out = lab / "next"
    code, text, err = _run(
        capsys, lab / "batch.json", "--design", lab / "design.json", "-o", out, "--no-preview",
        "--json",
    )  # fmt: skip
    assert code == 0, err
    summary = json.loads(text)
    assert summary["batch"]["model_form"] == [f"simulated {n}" for n in (EXACT, *OPTICAL_EFFECTS)]
    assert summary["correction"]["test"]["significant"]
    assert summary["correction"]["changed"]
    assert summary["prediction"]["gain"] > 0
    # the predicted next batch's angle error and margins, before and after
    figures = summary["figures"]
    assert figures["with"]["angle_deg"]["mean"] <= figures["without"]["angle_deg"]["mean"]
    assert min(figures["with"]["window_mm"]) > 0
    assert 0 < summary["correction"]["step"] <= 1
    assert summary["cad"]["printability"]["reflector"]["ok"]
    design = load_design(out / "design.json")
    block = design.correction
    assert block["batch"] == "B1" and block["sources"][0]["file"].endswith("batch.json")
    assert block["prediction"]["with"]["worst_resolution_deg"]["mean"] > 0
    assert design.reflector.centre_mm != drawn_design().reflector.centre_mm
    for name in ("reflector.stl", "reflector.3mf", "body.stl", "cad_report.json", "manifest.json"):
        assert (out / name).is_file()

    # the same units again, on the design they corrected: refused, nothing written
    again = lab / "again"
    code, _, err = _run(capsys, lab / "batch.json", "--design", out / "design.json", "-o", again)
    assert code == 2 and "already corrected from" in err
    assert err.count("\n") == 1 and not again.exists()


def test_correct_prints_what_it_changed_and_left(lab, capsys):
    code, text, err = _run(
        capsys, lab / "batch.json", "-o", lab / "text", "--no-preview", "--no-prediction",
        "--model-form", "none",
    )  # fmt: skip
    assert code == 0, err
    assert "batch 'B1': 4 unit(s) from 1 file(s)" in text
    assert "changes to the drawing (± std;" in text
    assert "rule: each resolved combination by max(0, 1 − (2/t)²)" in text
    assert "smallest margins, µm: window" in text
    assert "left as drawn, not determined by the data:" in text
    # the figures of the loss are always given; --no-prediction leaves out the calibration
    assert "design.json" in text and "calibration RMS" not in text


@pytest.mark.parametrize(
    ("files", "extra", "message"),
    [
        (["two_units"], [], r"2 unit\(s\) cannot tell a systematic deviation from the unit-to"),
        (["batch", "other_batch"], [], "batch 'B2', but .*batch.json: batch 'B1'"),
        (["batch"], ["--design", "other.json"], "is not the design the units of"),
        (["batch", "batch"], [], "the same identification as .*batch.json, given twice"),
    ],
)
def test_bad_input_is_one_line_exit_2_and_nothing_written(lab, capsys, files, extra, message):
    default_design().save(lab / "other.json")
    out = lab / "refused"
    extra = [str(lab / e) if e.endswith(".json") else e for e in extra]
    code, _, err = _run(
        capsys, *[lab / f"{f}.json" for f in files], *extra, "-o", out, "--model-form", "none"
    )
    assert code == 2
    assert err.count("\n") == 1 and "Traceback" not in err
    assert re.search(message, err), err
    assert not out.exists()


@pytest.mark.parametrize(
    "extra", [["--scatter-prior", "0"], ["--scatter-prior", "nan"], ["--level", "0"]]
)
def test_bad_options_are_one_line_exit_2_and_nothing_written(lab, capsys, extra):
    out = lab / "refused"
    code, _, err = _run(capsys, lab / "batch.json", *extra, "-o", out)
    assert code == 2
    assert f"{extra[0]}: expected a number > 0 and ≤" in err and "Traceback" not in err
    assert err.count("\n") == 1
    assert not out.exists()


def test_a_print_no_step_can_mend_is_refused_with_the_reason(lab, capsys):
    """Seats identified 1.5 mm too deep: the process already prints S1's strip proud of the
    envelope, and every step that would pull it back draws S1 inside the sphere, a design
    that cannot be built; nothing is written."""
    out = lab / "refused"
    code, _, err = _run(capsys, lab / "deep_seats.json", "-o", out, "--model-form", "none")
    assert code == 2
    # progress lines ("HH:MM:SS …") come before it; the error is one line
    errors = [line for line in err.splitlines() if not re.match(r"\d\d:\d\d:\d\d ", line)]
    assert len(errors) == 1 and "Traceback" not in err, err
    assert re.search(r"no step of the correction gives a printable part: .*'S1'", errors[0])
    assert not out.exists()


def test_two_units_are_corrected_when_the_user_takes_them_as_systematic(lab, capsys):
    code, text, err = _run(
        capsys, lab / "two_units.json", "--assume-systematic", "-o", lab / "two", "--no-preview",
        "--no-prediction", "--model-form", "none",
    )  # fmt: skip
    assert code == 0, err
    assert "fewer than 3 units cannot tell systematic from random" in text
    assert load_design(lab / "two" / "design.json").correction["assume_systematic"] is True


@pytest.mark.slow
def test_identify_records_the_batch_that_correct_checks(tmp_path, capsys):
    from reflector_opt.asbuilt._asbuiltfile import load_as_built
    from reflector_opt.calibration._files import write_calibration_csv
    from reflector_opt.calibration._plans import make_plan
    from reflector_opt.tolerance._builtunit import built_unit_protocol

    units, _ = printed("strong")
    design = drawn_design()
    design.save(tmp_path / "design.json")
    plan = make_plan(design.workspace, "grid", 49)
    calibration = built_unit_protocol(units[0], plan, n_validation=1, seed=1).calibration
    labels = ["1"] * len(plan)
    write_calibration_csv(tmp_path / "cal.csv", labels, calibration.volts, calibration.angles_deg)
    argv = ["identify", str(tmp_path / "cal.csv"), "--design", str(tmp_path / "design.json")]
    assert main([*argv, "--batch", " B1", "-o", str(tmp_path / "bad.json")]) == 2
    assert "batch: expected a name" in capsys.readouterr().err
    assert not (tmp_path / "bad.json").exists()
    assert main([*argv, "--batch", "B1", "--no-profiles", "-o", str(tmp_path / "a.json")]) == 0
    assert load_as_built(tmp_path / "a.json").batch == "B1"
    capsys.readouterr()
    # the model-form term identify records is the one correct weighs (nothing simulated)
    code, text, err = _run(
        capsys, tmp_path / "a.json", "--assume-systematic", "-o", tmp_path / "next",
        "--no-preview", "--no-prediction",
    )  # fmt: skip
    assert code == 0, err
    assert "model-form bias is weighed as an uncertainty (the identification files)" in text
