"""A one-line progress indicator for long work on a terminal.

Library functions take an optional ``progress(fraction, message)`` callable; the command line
passes a :class:`ProgressLine`, which redraws one line on stderr when stderr is a terminal
and stays silent otherwise (pipes, logs, CI) or when disabled (``--quiet``).
"""

from __future__ import annotations

import sys
import time

__all__ = ["ProgressLine"]


class ProgressLine:
    """Callable ``(fraction, message)`` that redraws ``[ 42%] message`` in place.

    Parameters
    ----------
    stream : file-like, optional
        Where to draw (default ``sys.stderr``).
    enabled : bool, optional
        Force on or off; by default on only if ``stream`` is a terminal.
    min_interval_s : float, optional
        Redraw at most this often, seconds.

    Use it as a context manager, so the line is ended when the work is done or fails.
    """

    def __init__(self, stream=None, enabled=None, min_interval_s=0.1):
        self.stream = sys.stderr if stream is None else stream
        if enabled is None:
            isatty = getattr(self.stream, "isatty", None)
            enabled = bool(isatty and isatty())
        self.enabled = enabled
        self.min_interval_s = min_interval_s
        self._last = -float("inf")
        self._width = 0

    def __call__(self, fraction, message):
        """Show ``fraction`` (0–1, clipped) and ``message``."""
        if not self.enabled:
            return
        now = time.monotonic()
        if now - self._last < self.min_interval_s and fraction < 1.0:
            return
        self._last = now
        pct = round(100 * min(max(float(fraction), 0.0), 1.0))
        text = f"[{pct:3d}%] {message}"
        self.stream.write("\r" + text.ljust(self._width))
        self.stream.flush()
        self._width = len(text)

    def close(self):
        """End the line, if anything was drawn."""
        if self.enabled and self._width:
            self.stream.write("\r" + " " * self._width + "\r")
            self.stream.flush()
            self._width = 0

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False
