"""Crash logs: the folder they go to, and a log holding the command line and the traceback."""

import os

import pytest

from reflector_opt import __version__
from reflector_opt.util._crashlog import log_folder, write_crash_log


def test_logs_go_to_the_cache_folder(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    folder = log_folder()
    assert folder == tmp_path / "cache" / "reflector-opt"
    assert folder.is_dir() and os.access(folder, os.W_OK)


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes anywhere")
def test_an_unwritable_cache_falls_back_to_the_temporary_folder(tmp_path, monkeypatch):
    blocked = tmp_path / "blocked"
    blocked.write_text("a file, not a folder", encoding="utf-8")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocked))
    monkeypatch.setenv("TMPDIR", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", None)
    folder = log_folder()
    assert folder.parent == tmp_path / "tmp" and os.access(folder, os.W_OK)


def test_a_log_holds_the_version_the_command_and_the_traceback(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    try:
        raise ZeroDivisionError("boom")
    except ZeroDivisionError as exc:
        path = write_crash_log(exc, ["reflector-opt", "evaluate", "d.json"])
    assert path.parent == tmp_path / "reflector-opt" and path.name.startswith("crash-")
    text = path.read_text(encoding="utf-8")
    assert text.startswith(f"reflector-opt {__version__}, ")
    assert "command: reflector-opt evaluate d.json\n" in text
    assert "Traceback" in text and text.rstrip().endswith("ZeroDivisionError: boom")
