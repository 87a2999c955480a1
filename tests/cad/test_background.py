"""Work made in a forked process: a result returned, files moved only when collected."""

import multiprocessing
import os

import pytest

from reflector_opt.cad._background import PRIVATE_NAME, BackgroundCall, BackgroundFiles
from reflector_opt.util._errors import InputError
from tests.processes import HAS_PROC, descendants, running


def _write_pid(folder):
    (folder / "made.txt").write_text(str(os.getpid()))


def test_files_are_made_in_another_process_and_moved_on_collect(tmp_path):
    out = tmp_path / "out"
    with BackgroundFiles(_write_pid) as job:
        paths = job.collect(out, ["made.txt"])
    assert paths == {"made.txt": out / "made.txt"}
    assert os.listdir(out) == ["made.txt"]
    if "fork" in multiprocessing.get_all_start_methods():
        assert int(paths["made.txt"].read_text()) != os.getpid()


def test_closing_without_collect_leaves_nothing(tmp_path):
    job = BackgroundFiles(_write_pid)
    folder = job._folder
    job.close()
    assert not folder.exists()
    assert list(tmp_path.iterdir()) == []


def test_a_failure_in_the_process_is_raised_by_collect(tmp_path):
    def refuse(folder):
        raise InputError("picture: cannot draw")

    with BackgroundFiles(refuse) as job, pytest.raises(InputError, match="cannot draw"):
        job.collect(tmp_path, ["made.txt"])
    assert list(tmp_path.iterdir()) == []


def test_an_unwritable_output_folder_is_one_input_error(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    with BackgroundFiles(_write_pid) as job, pytest.raises(InputError, match="cannot write"):
        job.collect(blocker / "out", ["made.txt"])


def _pid_and_square(x):
    return os.getpid(), x * x


def test_a_call_returns_its_result_from_another_process():
    with BackgroundCall(lambda: _pid_and_square(7)) as job:
        pid, square = job.result()
    assert square == 49
    if "fork" in multiprocessing.get_all_start_methods():
        assert pid != os.getpid()


def test_a_failed_call_is_run_again_in_the_caller_and_raises_there():
    calls = []

    def refuse():
        calls.append(os.getpid())
        raise InputError("proof: cannot prove")

    with BackgroundCall(refuse) as job, pytest.raises(InputError, match="cannot prove"):
        job.result()
    assert calls == [os.getpid()]  # the forked process's attempt is not seen here


@pytest.mark.skipif(not HAS_PROC, reason="reads processes from Linux's /proc")
def test_closing_a_running_call_stops_its_process():
    before = descendants(os.getpid())
    job = BackgroundCall(lambda: __import__("time").sleep(60))
    started = set(descendants(os.getpid())) - set(before)
    assert started, "the call runs in a process of its own"
    job.close()
    assert not any(running(pid) for pid in started)


def test_a_private_folder_left_by_a_killed_process_is_removed_by_the_next(tmp_path, monkeypatch):
    import tempfile

    from reflector_opt.util._atomic import TEMP_MARK

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    left = tmp_path / f"{TEMP_MARK}{PRIVATE_NAME}-abcd1234"
    left.mkdir()
    (left / "reflector.png").write_bytes(b"half a picture")
    os.utime(left, (0, 0))  # before this run started
    running = tmp_path / f"{TEMP_MARK}{PRIVATE_NAME}-efgh5678"  # another run's, in progress
    running.mkdir()
    with BackgroundFiles(_write_pid) as job:
        job.collect(tmp_path / "out", ["made.txt"])
    assert not left.exists() and running.exists()
