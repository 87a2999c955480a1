"""The report run writes the report the command writes."""

import json
from pathlib import Path

import pytest

import reflector_opt as ro
from reflector_opt.cli import main
from reflector_opt.design import load_design


@pytest.mark.slow
def test_report_run_writes_the_report_the_command_writes(coarse_design, tmp_path, capsys):
    by_command, by_call = tmp_path / "command", tmp_path / "call"
    assert (
        main(["report", str(coarse_design), "--no-cad", "-q", "--json", "-o", str(by_command)]) == 0
    )
    printed = json.loads(capsys.readouterr().out)

    run = ro.workflow.report(load_design(coarse_design), cad=False).write(by_call)
    for name in ("report.md", "report.html"):
        assert (by_call / name).read_bytes() == (by_command / name).read_bytes()
    assert [Path(p).name for p in printed["files"]] == [p.name for p in run.files]
    assert (
        printed["markdown"] == str(by_command / "report.md") and printed["cad"]["written"] is False
    )
    assert all(Path(p).is_file() for p in printed["files"])
    assert f"files written: {len(run.files)} in {by_call}" in repr(run)
    assert "not exported" in run._repr_html_()
