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
    assert in_use == in_use_block(ro.load_design(coarse_design))
    assert run.text().startswith("in use in the default conditions (docs/conditions.md) (±2 K")
    assert run.to_dict()["conditions"] == Conditions().to_dict()  # the budget in them too
    assert "worst case in use with the recommended form's misfit in: " in run.text()
