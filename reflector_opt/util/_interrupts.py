"""Ctrl-C and SIGTERM as exceptions; one that arrives while a library that would swallow it
is imported is held and raised after.

Some libraries guard their optional imports with ``except BaseException`` (trimesh does, in
about 140 places): a :class:`KeyboardInterrupt` raised while such a library is imported is
swallowed, the library is left with one of its dependencies replaced by a placeholder, and
the command runs on as if nothing had been pressed. :func:`interrupts_after_imports`
installs a SIGINT handler that raises the interrupt at once, except while the module-level
code of one of :data:`SWALLOWING_PACKAGES` runs: then it holds the interrupt and raises it
as soon as no import runs (checked every :data:`CHECK_S` seconds with a timer signal).

SIGTERM (``kill PID``, a job scheduler or a service manager stopping the command) is
handled the same way and raises :class:`Terminated`, a :class:`KeyboardInterrupt`, so the
command cleans up as after a Ctrl-C (its temporary files and folders removed, its worker
processes stopped) before it exits.
"""

import signal
import threading
from contextlib import contextmanager

#: Packages whose import swallows a KeyboardInterrupt.
SWALLOWING_PACKAGES = ("trimesh",)

#: How often a held interrupt checks whether the import is over, s.
CHECK_S = 0.02

_held = threading.Event()

#: The signals raised as exceptions.
_STOPS = (signal.SIGINT, signal.SIGTERM)


class Terminated(KeyboardInterrupt):
    """SIGTERM: a request to stop, handled as a Ctrl-C is."""


#: The exception of the last stop signal (what a held one raises).
_pending = [KeyboardInterrupt]


def _importing(frame, packages=None):
    """True if the Python stack at ``frame`` runs an import: of a module of ``packages``
    (its module-level code runs), or of any module if ``packages`` is None."""
    while frame is not None:
        if packages is None:
            if frame.f_code.co_filename.startswith("<frozen importlib"):
                return True
        elif frame.f_code.co_name == "<module>":
            if str(frame.f_globals.get("__name__", "")).partition(".")[0] in packages:
                return True
        frame = frame.f_back
    return False


def _interrupt(signum, frame):
    """SIGINT or SIGTERM, and the timer's SIGALRM while an interrupt is held.

    An interrupt is held if it arrives while a swallowing package is imported, and raised
    once no import at all runs: raised inside another module's import it could end up in
    code a C extension runs for its import, after which the interpreter, even with the
    interrupt handled, exits through SIGINT instead of with the command's exit code.
    """
    if signum == signal.SIGALRM and not _held.is_set():
        return
    if signum != signal.SIGALRM:
        _pending[0] = Terminated if signum == signal.SIGTERM else KeyboardInterrupt
        threading.excepthook = _stopping
    if _importing(frame, None if _held.is_set() else SWALLOWING_PACKAGES):
        _held.set()
        signal.setitimer(signal.ITIMER_REAL, CHECK_S)
        return
    _held.clear()
    raise _pending[0]


def _stopping(args):
    """The threads' exception hook once a stop signal came: a process pool whose workers the
    same signal stopped breaks in its management thread (``concurrent.futures`` sets the
    exception of a future the stop cancelled: InvalidStateError), which is the stop itself and
    not a second error to print beside the command's one line."""


@contextmanager
def interrupts_after_imports():
    """Within the block, SIGINT raises :class:`KeyboardInterrupt` and SIGTERM
    :class:`Terminated`; one that arrives while a swallowing package is imported is raised
    after that import.

    Installs handlers of SIGINT, SIGTERM and SIGALRM (restored afterwards); does nothing
    outside the main thread or where there are no interval timers.
    """
    if threading.current_thread() is not threading.main_thread() or not hasattr(
        signal, "setitimer"
    ):
        yield
        return
    _held.clear()
    previous = {s: signal.signal(s, _interrupt) for s in (*_STOPS, signal.SIGALRM)}
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        for s, handler in previous.items():
            signal.signal(s, handler)
        if _held.is_set():  # the block ended before the held interrupt was raised
            _held.clear()
            raise _pending[0]
