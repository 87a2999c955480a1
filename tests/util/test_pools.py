"""Process hygiene of the local pool: workers die with their parent, even on SIGKILL."""

import os
import signal
import subprocess
import textwrap

import pytest

from reflector_opt.util._atomic import TEMP_MARK
from tests.processes import HAS_PROC, descendants, running, start, wait_until

pytestmark = pytest.mark.skipif(not HAS_PROC, reason="reads processes from Linux's /proc")

BUSY_PARENT = textwrap.dedent(
    """
    import sys, time
    from reflector_opt.util._pools import local_processes
    from reflector_opt.util._fileio import atomic_path

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
    write = "from reflector_opt.util._fileio import write_text"
    next_run = f"{write}; write_text({str(target)!r}, 'complete')"
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

    from reflector_opt.util._pools import local_processes

    with pytest.raises(KeyboardInterrupt), local_processes(2)() as pool:
        busy = [pool.submit(time.sleep, 300) for _ in range(4)]
        workers = list(pool._processes)
        raise KeyboardInterrupt
    threads = [t for t in threading.enumerate() if isinstance(t, process._ExecutorManagerThread)]
    assert threads == []
    assert not any(running(pid) for pid in workers)
    assert all(future.done() for future in busy)


def test_workers_that_cannot_start_are_one_input_error(tmp_path):
    """Where workers are spawned (off Linux), a spawned worker imports ``__main__`` again; one
    read from stdin cannot be: the broken pool is one InputError saying what to do."""
    program = textwrap.dedent(
        """
        import operator
        from reflector_opt.util import _pools as pools
        from reflector_opt.util._errors import InputError

        pools.START_METHOD = "spawn"
        try:
            pools.run_batches(operator.mul, 3, [1, 2, 5], pools.local_processes(2))
        except InputError as exc:
            print(exc)
        """
    )
    run = start(["-"], cwd=tmp_path, stdin=subprocess.PIPE)
    out, _ = run.communicate(program, timeout=120)
    assert out.startswith("workers: the worker processes could not start"), out
    assert 'under `if __name__ == "__main__":`' in out
