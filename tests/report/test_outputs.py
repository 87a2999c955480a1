"""The report's files: the CAD export's outcome, and the output folder refused when it is a file.

The pages and parts themselves, written by ``write_design_outputs``, are checked end to end in
tests/report/test_report.py.
"""

from pathlib import Path

import pytest

from reflector_opt.report import _outputs as outputs
from reflector_opt.report._outputs import CadOutcome, export_cad, write_design_outputs, write_report
from reflector_opt.util._errors import InputError


def test_the_outcome_says_where_the_cad_report_went_or_why_nothing_was_written():
    written = CadOutcome(report={"report": "cad_report.json"})
    assert written.summary("out") == (
        f"wrote the printable parts; CAD report {Path('out') / 'cad_report.json'}"
    )
    failed = CadOutcome(error="body: wall 0.4 mm < 0.8 mm")
    assert failed.summary("out") == "no printable parts: body: wall 0.4 mm < 0.8 mm"


def test_a_failed_check_becomes_the_outcome_and_the_export_report_passes_through(
    design, tmp_path, monkeypatch
):
    calls = []

    def refuse(design, out_dir, progress=None):
        calls.append(Path(out_dir))
        raise InputError("reflector: shell 0.5 mm thick < 0.8 mm")

    monkeypatch.setattr(outputs, "export_parts", refuse)
    assert export_cad(design, tmp_path) == CadOutcome(
        error="reflector: shell 0.5 mm thick < 0.8 mm"
    )
    monkeypatch.setattr(outputs, "export_parts", lambda d, o, progress=None: {"report": "r"})
    assert export_cad(design, tmp_path) == CadOutcome(report={"report": "r"})
    assert calls == [tmp_path]


@pytest.mark.parametrize("write", [write_report, write_design_outputs])
def test_a_file_where_the_folder_should_be_is_refused_before_any_work(design, tmp_path, write):
    taken = tmp_path / "out"
    taken.write_text("not a folder")
    with pytest.raises(InputError, match="exists and is not a folder") as caught:
        write(design, taken)
    assert str(caught.value).count("\n") == 0 and str(taken) in str(caught.value)
    assert [p.name for p in tmp_path.iterdir()] == ["out"]
