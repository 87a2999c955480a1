"""Faults of the command line: interrupts, a full disk, internal errors, Ctrl-C with workers.

Each case once left a mix of old and new files, a partial folder, worker tracebacks or a
bare traceback: an interrupted command exits 130 with its output folder as it was, a full
disk is one line and exit 2, an internal error one line pointing to a log of its traceback.
"""

import errno
import json
import os
import re
import signal

import pytest

from reflector_opt.cli import main
from reflector_opt.design import default_design
from reflector_opt.util._atomic import MANIFEST, TEMP_MARK
from tests.processes import HAS_PROC, descendants, running, start, wait_until

SWEEP = ["sweep", "design.json", "--vary", "reflector.radius_mm=8.5:9.0:2", "--quiet"]


@pytest.fixture
def folder(tmp_path, monkeypatch):
    """A working folder with design.json, and a previous sweep's complete output in out/."""
    monkeypatch.chdir(tmp_path)
    default_design().save(tmp_path / "design.json")
    out = tmp_path / "out"
    out.mkdir()
    for name in ("sweep.csv", "sweep.png"):
        (out / name).write_text(f"previous {name}")
    return tmp_path


def _contents(out):
    return {p.name: p.read_bytes() for p in out.iterdir()}


def _temporaries(folder):
    return [p for p in folder.rglob("*") if TEMP_MARK in p.name]


def _raiser(exc):
    def fail(*args, **kwargs):
        raise exc

    return fail


@pytest.mark.parametrize(
    "where",
    [
        "reflector_opt.tolerance._output.write_records",
        "reflector_opt.report._plots.save_figure",
        "reflector_opt.util._atomic._carry_over",
        "reflector_opt.util._atomic._swap_in",
    ],
)
def test_an_interrupt_while_writing_leaves_the_previous_outputs(folder, capsys, monkeypatch, where):
    before = _contents(folder / "out")
    monkeypatch.setattr(where, _raiser(KeyboardInterrupt()))
    assert main([*SWEEP, "--out", "out"]) == 130
    assert capsys.readouterr().err == "reflector-opt: interrupted\n"
    assert _contents(folder / "out") == before and _temporaries(folder) == []


def test_sigterm_while_writing_is_one_line_143_and_leaves_the_previous_outputs(
    folder, capsys, monkeypatch
):
    """``kill PID`` once left the temporary folder of the new set behind (and, with
    workers, a resource tracker's warning of leaked semaphores): it is now handled as a
    Ctrl-C is, with its own exit code."""
    before = _contents(folder / "out")

    def terminate(*args, **kwargs):
        os.kill(os.getpid(), signal.SIGTERM)
        for _ in range(10**6):  # the handler raises between these bytecodes
            pass
        pytest.fail("SIGTERM was not raised")

    monkeypatch.setattr("reflector_opt.report._plots.save_figure", terminate)
    assert main([*SWEEP, "--out", "out"]) == 143
    assert capsys.readouterr().err == "reflector-opt: terminated\n"
    assert _contents(folder / "out") == before and _temporaries(folder) == []
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL


def test_a_complete_run_replaces_the_set_and_writes_its_manifest(folder, capsys):
    assert main([*SWEEP, "--out", "out"]) == 0
    manifest = json.loads((folder / "out" / MANIFEST).read_text())
    assert [f["path"] for f in manifest["files"]] == ["sweep.csv", "sweep.png"]
    assert manifest["command"] == ["reflector-opt", *SWEEP, "--out", "out"]
    assert (folder / "out" / "sweep.png").read_bytes()[:4] == b"\x89PNG"
    assert "  out/sweep.csv\n" in capsys.readouterr().out


def test_a_full_disk_is_one_line_and_leaves_the_previous_outputs(folder, capsys, monkeypatch):
    before = _contents(folder / "out")
    full = OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    monkeypatch.setattr("reflector_opt.report._plots.save_figure", _raiser(full))
    assert main([*SWEEP, "--out", "out"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot write out: No space left on device" in err, err
    assert _contents(folder / "out") == before and _temporaries(folder) == []


def test_an_internal_error_is_one_line_pointing_to_its_log(folder, capsys, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(folder / "cache"))
    bug = ZeroDivisionError("a bug\nwith a second line")
    monkeypatch.setattr("reflector_opt.tolerance._sweep.sweep", _raiser(bug))
    assert main([*SWEEP, "--out", "out"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert "reflector-opt sweep: internal error (ZeroDivisionError: a bug)" in err
    logs = list((folder / "cache" / "reflector-opt").glob("crash-*.log"))
    assert len(logs) == 1 and str(logs[0]) in err
    text = logs[0].read_text()
    assert "Traceback (most recent call last)" in text and "ZeroDivisionError: a bug" in text
    assert "command: reflector-opt sweep design.json" in text


#: How a running command is stopped: the signal, sent to its process group (what Ctrl-C in
#: a terminal and a service manager do) or to it alone (``kill PID``); its exit code and line.
STOPS = {
    "Ctrl-C": (signal.SIGINT, True, 130, "reflector-opt: interrupted\n"),
    "kill -INT PID": (signal.SIGINT, False, 130, "reflector-opt: interrupted\n"),
    "kill PID": (signal.SIGTERM, False, 143, "reflector-opt: terminated\n"),
    "kill -- -PGID": (signal.SIGTERM, True, 143, "reflector-opt: terminated\n"),
}


@pytest.mark.skipif(not HAS_PROC, reason="reads processes from Linux's /proc")
@pytest.mark.parametrize("stop", list(STOPS))
def test_a_stop_with_running_workers_is_one_line_its_exit_code_and_no_worker_left(folder, stop):
    signum, group, code, line = STOPS[stop]
    before = _contents(folder / "out")
    argv = ["-m", "reflector_opt", "tolerance", "design.json", "--samples", "20000"]
    process = start([*argv, "--out", "out", "--quiet"], cwd=folder)
    try:
        assert wait_until(lambda: len(descendants(process.pid)) >= 2, 120), "the pool started"
        workers = descendants(process.pid)
        wait_until(lambda: process.poll() is not None, 2)  # the batches get under way
        if group:
            os.killpg(process.pid, signum)
        else:
            process.send_signal(signum)
        _, err = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == code, err
    assert err.count("\n") == 1 and err == line, err  # no traceback of the pool at exit
    assert wait_until(lambda: not any(running(p) for p in workers), 30)
    assert _contents(folder / "out") == before and _temporaries(folder) == []


@pytest.fixture
def not_a_scheduler():
    """Address of a local TCP server that answers every connection with junk bytes, as a
    server of another protocol would."""
    import socketserver
    import threading

    class Junk(socketserver.BaseRequestHandler):
        def handle(self):
            self.request.sendall(b"\xffHTTP/1.1 400 Bad Request\r\n\r\n" * 8)

    with socketserver.ThreadingTCPServer(("127.0.0.1", 0), Junk) as server:
        threading.Thread(target=server.serve_forever, daemon=True).start()
        yield f"tcp://127.0.0.1:{server.server_address[1]}"
        server.shutdown()


@pytest.mark.parametrize(
    "address",
    [
        "foo://host:8786",
        "tcp://host:port",
        "tcp://127.0.0.1:1",
        # these ended in an internal error, or exit 2 after a teardown traceback
        "inproc://",
        "tls://127.0.0.1:1",
        "junk",
    ],
)
def test_a_bad_dask_address_is_one_line_without_a_teardown_traceback(folder, address, request):
    pytest.importorskip("distributed")
    if address == "junk":  # a server that is not a scheduler: a frame of exabytes was read
        address = request.getfixturevalue("not_a_scheduler")
    argv = ["-m", "reflector_opt", "tolerance", "design.json", "--samples", "4"]
    process = start([*argv, "--out", "new", "--scheduler", address], cwd=folder)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 2
    # a progress line ("HH:MM:SS …") may come first on a loaded machine, while the connection
    # waits out its timeout; the error itself is one line, and nothing else is written
    lines = [line for line in err.splitlines() if not re.match(r"\d\d:\d\d:\d\d ", line)]
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith("reflector-opt tolerance: error: ") and address in lines[0]
    assert not (folder / "new").exists()
