"""Worker processes end quietly when the command stops them."""

import time

import pytest

from reflector_opt.util._interrupts import interrupts_after_imports
from reflector_opt.util._pools import local_processes


def test_a_worker_stopped_by_the_command_leaves_no_traceback(capfd):
    """The search's forked pool inherited the command's SIGTERM handler: a Ctrl-C of
    ``optimise`` (which terminates the pool) printed a traceback per busy worker."""
    with interrupts_after_imports(), pytest.raises(KeyboardInterrupt):
        with local_processes(2)() as pool:
            busy = [pool.submit(time.sleep, 30) for _ in range(2)]
            time.sleep(0.5)  # the workers are asleep in their task
            raise KeyboardInterrupt
    assert all(future.done() for future in busy)
    err = capfd.readouterr().err
    assert "Traceback" not in err and "Terminated" not in err, err
