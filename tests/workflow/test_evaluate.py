"""The evaluate run is the command's summary; a design that cannot be read is refused."""

import json

import pytest

import reflector_opt as ro
from reflector_opt.cli import main
from reflector_opt.util.errors import InputError


def test_evaluate_run_is_the_command_summary(coarse_design, capsys):
    assert main(["evaluate", str(coarse_design), "--no-predict", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    run = ro.evaluate_run(coarse_design, predict=False)
    assert json.loads(json.dumps(run.to_dict())) == printed
    assert repr(run) == run.text()  # the command's printed summary, as every run with a text
    # a notebook shows what the command prints: a line per sensor among the ranges
    html = run._repr_html_()
    assert html.startswith("<pre>workspace: ") and html.count(" (NJL5901R-2): d ") == 2


def test_a_design_that_cannot_be_read_is_refused_and_nothing_written(tmp_path):
    missing = tmp_path / "missing.json"
    with pytest.raises(InputError, match="cannot read"):
        ro.evaluate_run(missing)
    with pytest.raises(InputError, match="cannot read"):
        ro.report_run(missing, out=tmp_path / "out")
    assert not (tmp_path / "out").exists()
