"""The evaluate run is the command's summary; a design that cannot be read is refused."""

import json

import pytest

import reflector_opt as ro
from reflector_opt.cli import main
from reflector_opt.util._errors import InputError


def test_evaluate_run_is_the_command_summary(coarse_design, capsys):
    assert main(["evaluate", str(coarse_design), "--no-predict", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    run = ro.evaluate(coarse_design, predict=False)
    assert json.loads(json.dumps(run.to_dict())) == printed
    assert repr(run) == run.text()  # the command's printed summary, as every run with a text
    # a notebook shows what the command prints: a line per sensor among the ranges
    html = run._repr_html_()
    assert html.startswith("<pre>in use in ") and html.count(" (NJL5901R-2): d ") == 2


def test_a_design_that_cannot_be_read_is_refused_and_nothing_written(tmp_path):
    missing = tmp_path / "missing.json"
    with pytest.raises(InputError, match="cannot read"):
        ro.evaluate(missing)
    with pytest.raises(InputError, match="cannot read"):
        ro.workflow.report(missing)
    assert not (tmp_path / "out").exists()


def test_evaluate_opens_with_the_figures_in_use_in_the_default_conditions(coarse_design):
    """The JSON's ``in_use`` has the keys of optimise's ``predicted["conditions"]``, in the
    default conditions when none are given; the text's first line names them."""
    from reflector_opt.design._conditions import Conditions
    from reflector_opt.report._conditions import in_use_block

    run = ro.evaluate(coarse_design, predict=False)
    in_use = run.to_dict()["in_use"]
    assert next(iter(run.to_dict())) == "in_use"
    keys = {"worst_case_deg", "worst_pitch_deg", "worst_roll_deg", "median_deg", "binding"}
    assert keys | {"rms_deg", "white_noise_floor_deg", "baseline", "improvement"} <= set(in_use)
    assert {"worst_case_deg", "median_deg", "binding"} <= set(in_use["baseline"])
    assert in_use == in_use_block(ro.load_design(coarse_design)).to_dict()
    assert run.text().startswith("in use in the default conditions (docs/conditions.md) (±2 K")
    assert run.to_dict()["conditions"] == Conditions().to_dict()  # the budget in them too
    assert "worst case in use with the recommended form's misfit in: " in run.text()


def _recording(design, table):
    """``design`` recording the conditions ``table`` with the figures in use optimise writes."""
    from reflector_opt.report._conditions import in_use_block

    block = in_use_block(design).to_dict() | {"conditions": table}
    return design.replace(predicted={"conditions": block})


def test_evaluate_judges_a_design_in_the_read_out_it_records_unless_told_otherwise(
    coarse_design, tmp_path
):
    """A design whose optimise run chose a switched, temperature-compensated read-out is
    judged in it (the headline says so); ``conditions`` overrides; a design that records the
    default conditions, or none, is judged in the defaults."""
    from reflector_opt.analysis._budget import error_budget
    from reflector_opt.design._conditions import Conditions
    from reflector_opt.workflow._evaluate import RECORDED

    chosen = Conditions().replace(drive="modulated", sample_rate_hz=310.0)
    chosen = chosen.replace(temperature_compensated=True)
    design = ro.load_design(coarse_design)
    path = tmp_path / "design.json"
    _recording(design, chosen.to_dict()).save(path)
    in_use = ro.evaluate(path, predict=False).to_dict()["in_use"]
    assert in_use["conditions"] == chosen.to_dict()
    assert in_use["conditions_source"] == RECORDED
    expected = error_budget(design, chosen).worst_case_deg
    assert in_use["worst_case_deg"] == pytest.approx(expected, rel=1e-12)
    default = error_budget(design, Conditions()).worst_case_deg
    assert abs(expected / default - 1.0) > 0.01  # the read-out moves the figure
    text = ro.evaluate(path, predict=False).text()
    assert text.startswith(f"in use in {RECORDED} (±2 K, modulated drive at 310 Sa/s, temp")
    overridden = ro.evaluate(path, predict=False, conditions=Conditions()).to_dict()["in_use"]
    assert overridden["conditions"]["drive"] == "dc"
    assert overridden["worst_case_deg"] == pytest.approx(default, rel=1e-12)
    _recording(design, Conditions().to_dict()).save(path)
    assert ro.evaluate(path, predict=False).to_dict()["in_use"]["conditions_source"] == (
        "the default conditions (docs/conditions.md)"
    )


def test_a_recorded_table_no_longer_read_is_refused_naming_the_key(coarse_design, tmp_path):
    from reflector_opt.design._conditions import Conditions

    table = Conditions().to_dict() | {"joint_play_um": 5.0}
    path = tmp_path / "design.json"
    design = ro.load_design(coarse_design)
    _recording(design, table).save(path)
    with pytest.raises(InputError, match=r"predicted\.conditions: conditions\.joint_play_um"):
        ro.evaluate(path, predict=False)
    assert ro.evaluate(path, predict=False, conditions=Conditions()).to_dict()["in_use"]
