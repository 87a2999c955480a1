"""Process hygiene of the local pool: workers die with their parent, even on SIGKILL."""

import os
import signal
import textwrap

import pytest

from reflector_opt.util.atomic import TEMP_MARK
from tests.processes import HAS_PROC, descendants, running, start, wait_until

pytestmark = pytest.mark.skipif(not HAS_PROC, reason="reads processes from Linux's /proc")

BUSY_PARENT = textwrap.dedent(
    """
    import sys, time
    from reflector_opt.util.pools import local_processes
    from reflector_opt.util.fileio import atomic_path

    with local_processes(2)() as pool:
        busy = [pool.submit(time.sleep, 300) for _ in range(2)]
        with atomic_path(sys.argv[1]) as tmp:
            tmp.write_text("half", encoding="utf-8")
            print("ready", flush=True)
            time.sleep(300)
    """
)


def test_sigkill_of_the_parent_leaves_no_worker_and_the_next_write_no_temporary(tmp_path):
    target = tmp_path / "result.txt"
    parent = start(["-c", BUSY_PARENT, str(target)], cwd=tmp_path)
    try:
        assert parent.stdout.readline().strip() == "ready", parent.stderr.read()
        workers = wait_until(lambda: (found := descendants(parent.pid)) and len(found) >= 2, 60)
        assert workers, "the pool started its workers"
        workers = descendants(parent.pid)
        os.kill(parent.pid, signal.SIGKILL)
        parent.wait(30)
    finally:
        if parent.poll() is None:
            parent.kill()
    alive = wait_until(lambda: [p for p in workers if running(p)] == [], 30)
    assert alive, f"workers outlived their parent: {[p for p in workers if running(p)]}"
    left = [p.name for p in tmp_path.iterdir() if TEMP_MARK in p.name]
    assert len(left) == 1 and not target.exists()  # what a SIGKILL cannot clean up ...
    next_run = (
        f"from reflector_opt.util.fileio import write_text; write_text({str(target)!r}, 'complete')"
    )
    start(["-c", next_run], cwd=tmp_path).wait(60)  # ... the next run's write of the file removes
    assert [p.name for p in tmp_path.iterdir()] == ["result.txt"]
    assert target.read_text() == "complete"


def test_an_interrupt_stops_the_workers_and_joins_the_pool_thread():
    """The pool's thread outlived an interrupt: still closing its pipes at the interpreter's
    exit, it raced the exit's own wake-up of it, a traceback after the one line of Ctrl-C
    ('Exception ignored in … threading._shutdown … OSError: [Errno 9] Bad file descriptor')."""
    import threading
    import time
    from concurrent.futures import process

    from reflector_opt.util.pools import local_processes

    with pytest.raises(KeyboardInterrupt), local_processes(2)() as pool:
        busy = [pool.submit(time.sleep, 300) for _ in range(4)]
        workers = list(pool._processes)
        raise KeyboardInterrupt
    threads = [t for t in threading.enumerate() if isinstance(t, process._ExecutorManagerThread)]
    assert threads == []
    assert not any(running(pid) for pid in workers)
    assert all(future.done() for future in busy)


def test_where_no_worker_can_start_the_batches_run_here_with_one_warning(monkeypatch):
    """Off Linux, a script that spawned workers would re-run is not forked (unsafe there):
    the work runs in this process, and a warning says why and what to do."""
    import operator
    import sys

    from reflector_opt.util import workers
    from reflector_opt.util.pools import local_processes, run_batches

    monkeypatch.setattr(workers, "main_rerun_reason", lambda: "script.py is running code")
    monkeypatch.setattr(sys, "platform", "darwin")
    before = descendants(os.getpid())
    with pytest.warns(RuntimeWarning, match=r"no worker processes \(script.py is running"):
        results = run_batches(operator.mul, 3, [1, 2, 5], local_processes(2))
    assert results == [3, 6, 15]
    assert descendants(os.getpid()) == before
    with pytest.raises(ZeroDivisionError), pytest.warns(RuntimeWarning):
        run_batches(operator.truediv, 3, [1, 0], local_processes(2))
