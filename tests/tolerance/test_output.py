"""A tolerance study's files: one CSV row per sample with NaN as an empty cell, and its summary."""

import csv
import json
import math
from types import SimpleNamespace

from reflector_opt.tolerance._output import write_records, write_study


def _rows(path):
    with path.open(newline="", encoding="utf-8") as handle:
        return list(csv.reader(handle))


def test_records_are_written_one_row_each_with_nan_empty(tmp_path):
    path = tmp_path / "samples.csv"
    write_records(path, [{"index": 0, "rms_deg": 0.25}, {"index": 1, "rms_deg": math.nan}])
    assert _rows(path) == [["index", "rms_deg"], ["0", "0.25"], ["1", ""]]
    assert float(_rows(path)[1][1]) == 0.25  # a float written in full (repr)


def test_no_records_give_an_empty_table(tmp_path):
    path = tmp_path / "samples.csv"
    write_records(path, [])
    assert _rows(path) in ([], [[]])


def test_a_study_writes_its_samples_and_summary(tmp_path):
    study = SimpleNamespace(records=[{"index": 0, "ok": True}], to_dict=lambda: {"yield": 1.0})
    files = write_study(tmp_path, study)
    assert files == [tmp_path / "samples.csv", tmp_path / "summary.json"]
    assert _rows(files[0]) == [["index", "ok"], ["0", "True"]]
    assert json.loads(files[1].read_text(encoding="utf-8"))["yield"] == 1.0
