"""A Ctrl-C during an import, held until the import is over and then raised.

Some libraries guard their optional imports with ``except BaseException`` (trimesh does, in
about 140 places): a :class:`KeyboardInterrupt` raised while such a library is imported is
swallowed, the library is left with one of its dependencies replaced by a placeholder, and
the command runs on as if nothing had been pressed. :func:`interrupts_after_imports`
installs a SIGINT handler that raises the interrupt at once outside imports and, during an
import, holds it and raises it as soon as no import is running (checked every
:data:`CHECK_S` seconds with a timer signal).
"""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager

__all__ = ["CHECK_S", "interrupts_after_imports"]

#: How often a held interrupt checks whether the import is over, s.
CHECK_S = 0.02

_held = threading.Event()


def _importing(frame):
    """True if the Python stack at ``frame`` runs an import."""
    while frame is not None:
        if frame.f_code.co_filename.startswith("<frozen importlib"):
            return True
        frame = frame.f_back
    return False


def _interrupt(signum, frame):
    """SIGINT, and the timer's SIGALRM while an interrupt is held."""
    if signum == signal.SIGALRM and not _held.is_set():
        return
    if _importing(frame):
        _held.set()
        signal.setitimer(signal.ITIMER_REAL, CHECK_S)
        return
    _held.clear()
    raise KeyboardInterrupt


@contextmanager
def interrupts_after_imports():
    """Within the block, a Ctrl-C that arrives during an import is raised after it.

    Installs handlers of SIGINT and SIGALRM (restored afterwards); does nothing outside the
    main thread or where there are no interval timers.
    """
    if threading.current_thread() is not threading.main_thread() or not hasattr(
        signal, "setitimer"
    ):
        yield
        return
    _held.clear()
    previous = {s: signal.signal(s, _interrupt) for s in (signal.SIGINT, signal.SIGALRM)}
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        for s, handler in previous.items():
            signal.signal(s, handler)
        if _held.is_set():  # the block ended before the held interrupt was raised
            _held.clear()
            raise KeyboardInterrupt
