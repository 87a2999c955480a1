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

:func:`worker_context` chooses how workers start. Spawned workers (the default) import
``__main__`` again; where that would run the caller's own code once more — a script (or a
``python -m`` module) whose statement running now is not under ``if __name__ ==
"__main__":``, or a script read from stdin, which no worker can read again — workers are
forked instead, or, where forking is unsafe (not Linux), none is started.
"""

from __future__ import annotations

import ast
import ctypes
import ctypes.util
import multiprocessing
import os
import signal
import sys
from multiprocessing.context import ForkContext, ForkProcess, SpawnContext, SpawnProcess

__all__ = ["init_worker", "live_workers", "spawn_context", "stop_processes", "worker_context"]

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


def _start_deaf(start, process):
    """Start ``process`` with SIGINT blocked; the caller's mask is restored after."""
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        start(process)
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)


class _SpawnedWorker(SpawnProcess):
    """A spawned process started with SIGINT blocked (the parent's mask is restored)."""

    def start(self):
        """Start the process; a Ctrl-C meanwhile reaches the parent once it is started."""
        _start_deaf(SpawnProcess.start, self)


class _ForkedWorker(ForkProcess):
    """A forked process started with SIGINT blocked (the parent's mask is restored)."""

    def start(self):
        """Start the process; a Ctrl-C meanwhile reaches the parent once it is started."""
        _start_deaf(ForkProcess.start, self)


class _SpawnWorkers(SpawnContext):
    Process = _SpawnedWorker


class _ForkWorkers(ForkContext):
    Process = _ForkedWorker


def live_workers():
    """The running worker processes this process started (of any pool of this module's
    contexts), including one started so recently that its pool does not list it yet.

    Returns
    -------
    set of multiprocessing.Process
    """
    kinds = (_SpawnedWorker, _ForkedWorker)
    return {p for p in multiprocessing.active_children() if isinstance(p, kinds)}


def spawn_context():
    """A ``multiprocessing`` spawn context whose processes start deaf to Ctrl-C.

    Returns
    -------
    multiprocessing.context.SpawnContext
        For ``ProcessPoolExecutor(mp_context=...)``, with ``initializer=init_worker``.
    """
    return _SpawnWorkers()


def _is_main_guard(test):
    """True for the expression ``__name__ == "__main__"`` (either way round)."""
    if not (isinstance(test, ast.Compare) and [type(op) for op in test.ops] == [ast.Eq]):
        return False
    sides = (test.left, *test.comparators)
    names = [side.id for side in sides if isinstance(side, ast.Name)]
    strings = [side.value for side in sides if isinstance(side, ast.Constant)]
    return names == ["__name__"] and strings == ["__main__"]


def _running_under_guard(main, source):
    """True if the top-level statement of ``main`` running now is ``if __name__ ==
    "__main__":`` and the line running is in its body (read from the file ``source``)."""
    frame = sys._getframe()
    while frame is not None and not (
        frame.f_code.co_name == "<module>" and frame.f_globals is vars(main)
    ):
        frame = frame.f_back
    if frame is None:  # not running the module: a re-import would run all of it again
        return False
    try:
        with open(source, encoding="utf-8") as handle:
            tree = ast.parse(handle.read())
    except (OSError, UnicodeDecodeError, SyntaxError, ValueError):
        return False
    line = frame.f_lineno
    for statement in tree.body:
        if statement.lineno <= line <= statement.end_lineno:
            return (
                isinstance(statement, ast.If)
                and _is_main_guard(statement.test)
                and statement.body[0].lineno <= line <= statement.body[-1].end_lineno
            )
    return False


def main_rerun_reason():
    """Why a spawned worker could not start here, or None if it can.

    A spawned worker imports the parent's ``__main__`` again, as ``__mp_main__``. That is
    nothing for ``python -c``, an interactive session or a notebook (no file), harmless under
    ``if __name__ == "__main__":``, and fatal otherwise: an unguarded script would run its own
    work again in every worker (which then dies trying to start workers of its own), and a
    script read from stdin cannot be read again.

    Returns
    -------
    str or None
        The reason, for a message.
    """
    main = sys.modules.get("__main__")
    spec = getattr(main, "__spec__", None)
    source = getattr(spec, "origin", None) or getattr(main, "__file__", None)
    if main is None or source is None:
        return None
    if not os.path.isfile(source):
        return f"__main__ is read from {source}, which a worker cannot read again"
    if _running_under_guard(main, source):
        return None
    return (
        f'{source} is running code outside `if __name__ == "__main__":`, '
        "which each spawned worker would run again"
    )


def worker_context():
    """The ``multiprocessing`` context local workers start from, and why not spawn.

    Returns
    -------
    (multiprocessing.context.BaseContext or None, str or None)
        Spawn (deaf to Ctrl-C, as :func:`spawn_context`) where :func:`main_rerun_reason`
        finds nothing; otherwise fork on Linux (the workers inherit this process, nothing
        is imported again) and None elsewhere, where forking a process that may hold
        threads is unsafe (then the work is to run in this process); and the reason.
    """
    reason = main_rerun_reason()
    if reason is None:
        return spawn_context(), None
    if sys.platform.startswith("linux"):
        return _ForkWorkers(), reason
    return None, reason
