"""What a command shows besides its result: log lines and progress on stderr, and the closing
lines with the files written and the wall time."""

import logging
import re
import time
from pathlib import Path

import pytest

from reflector_opt.cli import main
from reflector_opt.cli._output import console_logging, written_lines
from reflector_opt.util._errors import InputError
from reflector_opt.workflow._runs import cad_files


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
    names = ["r.stl", "r.3mf", "r.png", "a.png", "a_s.png", "cad_report.json"]
    assert cad_files(report, "out") == [Path("out") / name for name in names]
    assert cad_files(None, "out") == []


def test_console_logging_levels_and_format(capsys):
    log = logging.getLogger("reflector_opt.some.module")
    with console_logging("reflector-opt demo"):
        log.info("a step")
        log.debug("a detail")
        log.warning("careful")
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2
    assert re.fullmatch(r"\d\d:\d\d:\d\d a step", err[0])
    assert err[1] == "reflector-opt demo: warning: careful"

    with console_logging("reflector-opt demo", verbose=1):
        log.debug("a detail")
    assert capsys.readouterr().err.endswith(" a detail\n")

    with console_logging("reflector-opt demo", quiet=True):
        log.info("a step")
        log.warning("careful")
    assert capsys.readouterr().err == "reflector-opt demo: warning: careful\n"

    log.warning("after the command")  # the handler is gone; nothing reaches stderr from it
    assert "reflector-opt demo" not in capsys.readouterr().err
    assert not logging.getLogger("reflector_opt").handlers


def test_warnings_are_held_until_the_work_begins_and_dropped_if_the_input_is_refused(capsys):
    """A design read as a mirror and then refused printed the warning before its error."""
    log = logging.getLogger("reflector_opt.some.module")
    with pytest.raises(InputError), console_logging("reflector-opt demo"):
        log.warning("read as a mirror")
        raise InputError("refused")
    assert capsys.readouterr().err == ""

    with console_logging("reflector-opt demo", quiet=True):
        log.warning("read as a mirror")
        assert capsys.readouterr().err == ""  # held while the input is read
        log.debug("a step begins")  # not shown, but the work has begun
        assert capsys.readouterr().err == "reflector-opt demo: warning: read as a mirror\n"
        log.warning("later")  # shown at once
        assert capsys.readouterr().err == "reflector-opt demo: warning: later\n"

    with pytest.raises(KeyboardInterrupt), console_logging("reflector-opt demo"):
        log.warning("read as a mirror")
        raise KeyboardInterrupt  # the one line 'interrupted' stands alone too
    assert capsys.readouterr().err == ""


def test_a_command_logs_plain_progress_lines_off_a_terminal_and_none_when_quiet(
    capsys, monkeypatch
):
    monkeypatch.setattr("reflector_opt.util._progress.DELAY_S", 0.0)  # log even quick work
    assert main(["evaluate", "--no-predict"]) == 0
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert "\r" not in captured.err
    assert lines[0].endswith(" s)") and "  0% distance and voltage windows (" in lines[0]
    assert "100% evaluated (" in lines[-1]
    assert "design stays inside the sensor range" in captured.out  # the result on stdout

    assert main(["evaluate", "--no-predict", "--quiet"]) == 0
    assert capsys.readouterr().err == ""
