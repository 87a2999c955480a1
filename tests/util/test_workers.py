"""Worker processes end quietly when the command stops them."""

import multiprocessing
import os
import time

import pytest

from reflector_opt.util.interrupts import interrupts_after_imports
from reflector_opt.util.workers import init_worker


def _started(_):
    return os.getpid()


@pytest.mark.skipif(
    "fork" not in multiprocessing.get_all_start_methods(), reason="forks the workers"
)
def test_a_forked_worker_stopped_by_the_command_leaves_no_traceback(capfd):
    """The search's forked pool inherited the command's SIGTERM handler: a Ctrl-C of
    ``optimise`` (which terminates the pool) printed a traceback per busy worker."""
    with interrupts_after_imports():
        pool = multiprocessing.get_context("fork").Pool(2, init_worker, (os.getpid(),))
        try:
            pool.map(_started, range(2))
            pool.map_async(time.sleep, [30, 30])
            time.sleep(0.5)  # the workers are asleep in their task
        finally:
            pool.terminate()
            pool.join()
    err = capfd.readouterr().err
    assert "Traceback" not in err and "Terminated" not in err, err
