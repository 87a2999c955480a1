"""The closing lines of the subcommands: the files written and the wall time."""

import time

from reflector_opt.cli.output import cad_files, written_lines


def test_written_lines_list_each_path_once_after_the_count_and_time():
    started = time.perf_counter() - 2.0
    text = written_lines(["a/x.json", "a/y.png", "a/x.json"], started)
    head, *paths = text.splitlines()
    assert paths == ["  a/x.json", "  a/y.png"]
    count, seconds = head.removeprefix("wrote ").split(" files in ")
    assert count == "2" and 2.0 <= float(seconds.removesuffix(" s:")) < 60.0


def test_one_file_and_none():
    assert written_lines(["c.json"], time.perf_counter()).startswith("wrote 1 file in ")
    assert written_lines([], time.perf_counter()).startswith("nothing written (")


def test_cad_files_lists_every_file_of_the_export_report():
    report = {
        "files": {
            "reflector": {"stl": "r.stl", "3mf": "r.3mf", "png": "r.png", "triangles": 3},
            "assembly": {"png": "a.png", "section_png": "a_s.png", "png_bytes": 10},
        },
        "report": "cad_report.json",
    }
    assert cad_files(report) == ["r.stl", "r.3mf", "r.png", "a.png", "a_s.png", "cad_report.json"]
    assert cad_files(None) == []
