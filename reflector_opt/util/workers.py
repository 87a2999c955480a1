"""Worker processes that leave with their parent and leave Ctrl-C to it.

Ctrl-C in a terminal sends SIGINT to the whole process group; the parent alone should
handle it, so that the terminal shows one line instead of a traceback per worker. Workers
of :func:`spawn_context` start with SIGINT blocked (the mask survives ``exec``, so even a
worker still importing is deaf to it) and :func:`init_worker`, the initializer of every pool,
ignores it for good, lets SIGTERM end the worker at once (a forked worker would otherwise
raise the command's exception for it) and, on Linux, asks the kernel to kill the worker
when its parent dies (``prctl(PR_SET_PDEATHSIG, SIGKILL)``), which also covers a parent
killed by SIGKILL.
:func:`stop_processes` ends a pool's workers at once when the parent gives up on their work
(an interrupt, an error).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import signal
import sys
from multiprocessing.context import SpawnContext, SpawnProcess

__all__ = ["init_worker", "spawn_context", "stop_processes"]

_PR_SET_PDEATHSIG = 1


def _die_with_parent():
    """Ask Linux to SIGKILL this process when its parent exits; False where unsupported."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or None, use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def init_worker(parent_pid):
    """Initializer of a worker process (``initializer=init_worker, initargs=(os.getpid(),)``).

    Parameters
    ----------
    parent_pid : int
        The process id of the parent; if the parent is already gone when the worker starts
        (it died before the request to die with it took effect), the worker exits.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # A forked worker inherits the command's SIGTERM handler (reflector_opt.util.interrupts),
    # which would make the parent's stop (SIGTERM) a traceback in the worker: end quietly.
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _die_with_parent()
    if os.getppid() != parent_pid:
        os._exit(1)


def stop_processes(processes, timeout_s=5.0):
    """Terminate worker processes and wait for them (SIGKILL after ``timeout_s`` seconds).

    Parameters
    ----------
    processes : iterable of multiprocessing.Process
    timeout_s : float
    """
    processes = [p for p in processes if p.is_alive()]
    for p in processes:
        p.terminate()
    for p in processes:
        p.join(timeout_s)
        if p.is_alive():
            p.kill()
            p.join()


class _WorkerProcess(SpawnProcess):
    """A spawned process started with SIGINT blocked (the parent's mask is restored)."""

    def start(self):
        """Start the process; a Ctrl-C meanwhile reaches the parent once it is started."""
        blocked = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:
            super().start()
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, blocked)


class _WorkerContext(SpawnContext):
    Process = _WorkerProcess


def spawn_context():
    """A ``multiprocessing`` spawn context whose processes start deaf to Ctrl-C.

    Returns
    -------
    multiprocessing.context.SpawnContext
        For ``ProcessPoolExecutor(mp_context=...)``, with ``initializer=init_worker``.
    """
    return _WorkerContext()
