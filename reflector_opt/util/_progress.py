"""Progress of long work: a tqdm bar on a terminal, plain log lines everywhere else.

Library functions take an optional ``progress(fraction, message)`` callable and call it as
their work advances; they never print. The command line passes a :class:`Progress`, which
draws a tqdm bar on stderr when stderr is a terminal and otherwise (CI, notebooks, log
files) logs a plain line through the ``reflector_opt.util._progress`` logger once the work
has run for ``delay_s`` seconds, then at most every ``interval_s`` seconds and when a step
completes, so a log shows long work advancing without control characters, and quick work (or
input refused at once, whose one-line error stands alone) logs nothing. Each new message is
also logged at DEBUG level (``reflector-opt … -v``), with the time since the start.

The line is fitted to the terminal's width at every redraw (one column short of it, so that it
never wraps and each carriage return rewrites it in place; below 60 columns without the bar, so
that the percentage and the step stay in view). A terminal that reports no width
(0 columns, as some pseudo-terminals and containers do, or an error) gets a bar of
:data:`FALLBACK_COLUMNS`; ``COLUMNS`` set to a positive number overrides the reported width,
as it does for :func:`shutil.get_terminal_size`.

A command's work is several phases (a search, a polish, a prediction, a report). Each phase
reports its own fraction from 0 to 1; :class:`Phases` gives every phase its share of the
one display by weight (the work it does, measured), so that the percentage is the share of
the whole work done and never runs backwards (:func:`monotone`, :func:`scaled`).
"""

import logging
import os
import sys
import threading
import time

logger = logging.getLogger(__name__)

#: Steps of the bar: a fraction is shown to 0.1 %.
_STEPS = 1000
#: Least time between two redraws of the bar, s.
_REDRAW_S = 0.1
#: Work shorter than this logs no plain line, s (a step that can take longer shows progress).
DELAY_S = 2.0
#: How often the display is renewed while a step runs without reports, s.
HEARTBEAT_S = 1.0
#: Width of the bar, in columns, on a terminal that reports none (0 columns or an error).
FALLBACK_COLUMNS = 40
#: The line on a terminal of at least :data:`_BAR_COLUMNS` columns, and on a narrower one
#: (no bar, so that the percentage and the step stay in view).
_WIDE_FORMAT = "{percentage:3.0f}%|{bar:20}| {desc} [{elapsed}]"
_NARROW_FORMAT = "{percentage:3.0f}% {desc} [{elapsed}]"
_BAR_COLUMNS = 60


def no_progress(fraction, message):
    """A ``progress(fraction, message)`` that shows nothing, for a library call given none."""


class _Monotone:
    """``progress`` that shows the largest fraction reported so far (see :func:`monotone`)."""

    def __init__(self, progress):
        self.progress = progress
        self.fraction = 0.0

    def __call__(self, fraction, message):
        self.fraction = max(self.fraction, _clipped(fraction))
        self.progress(self.fraction, message)


def _clipped(fraction):
    return min(max(float(fraction), 0.0), 1.0)


def monotone(progress):
    """A ``progress(fraction, message)`` that never runs backwards.

    A fraction below one reported before is shown as that one (with the new message); a
    fraction outside 0–1 is clipped.

    Parameters
    ----------
    progress : callable or None
        ``progress(fraction, message)``; None shows nothing.

    Returns
    -------
    callable
        ``progress`` itself if it is already monotone.
    """
    if isinstance(progress, _Monotone):
        return progress
    return _Monotone(no_progress if progress is None else progress)


def scaled(progress, start, stop):
    """The progress of one phase: its fraction 0–1 shown from ``start`` to ``stop``.

    Parameters
    ----------
    progress : callable or None
        The whole work's ``progress(fraction, message)``; made :func:`monotone`.
    start, stop : float
        The share of the whole work done when the phase begins and when it ends (0–1).

    Returns
    -------
    callable
        ``progress(fraction, message)`` of the phase.
    """
    whole = monotone(progress)
    return lambda fraction, message: whole(start + (stop - start) * _clipped(fraction), message)


class Phases:
    """One display split into consecutive phases, each with its share of the work.

    Parameters
    ----------
    progress : callable or None
        ``progress(fraction, message)`` of the whole work; made :func:`monotone`.
    weights : mapping of str to float
        Each phase that runs, in order, and its work in any unit (e.g. seconds measured on
        the defaults); a phase of weight 0 is shown as an instant step.

    Examples
    --------
    >>> shown = []
    >>> phases = Phases(lambda f, m: shown.append(round(f, 2)), {"search": 3, "report": 1})
    >>> phases("search")(0.5, "generation 10")
    >>> phases("report")(0.0, "writing")
    >>> phases("search")(1.0, "late")  # never backwards
    >>> shown
    [0.38, 0.75, 0.75]
    """

    def __init__(self, progress, weights):
        self.progress = monotone(progress)
        total = float(sum(weights.values()))
        self._bounds, done = {}, 0.0
        for name, weight in weights.items():
            share = weight / total if total > 0 else 0.0
            self._bounds[name] = (done, min(done + share, 1.0))
            done += share

    def __call__(self, name):
        """The ``progress(fraction, message)`` of phase ``name``."""
        return scaled(self.progress, *self._bounds[name])

    def finish(self, message):
        """Show the whole work done (100 %) with ``message``."""
        self.progress(1.0, message)


def _is_terminal(stream):
    isatty = getattr(stream, "isatty", None)
    try:
        return bool(isatty and isatty())
    except ValueError:  # a closed stream
        return False


def terminal_columns(stream):
    """Columns of the terminal ``stream`` is drawn on; :data:`FALLBACK_COLUMNS` if unknown.

    ``COLUMNS`` in the environment, if a positive whole number, wins (as for
    :func:`shutil.get_terminal_size`); then the terminal's own report; a report of 0 columns
    or none at all (not a terminal, a closed stream) counts as unknown.

    Parameters
    ----------
    stream : file-like

    Returns
    -------
    int
        At least 1.
    """
    env = os.environ.get("COLUMNS", "")
    if env.isdigit() and int(env) > 0:
        return int(env)
    try:
        columns = os.get_terminal_size(stream.fileno()).columns
    except (AttributeError, OSError, ValueError):  # no file descriptor, not a terminal, closed
        columns = 0
    return columns if columns > 0 else FALLBACK_COLUMNS


class Progress:
    """Callable ``(fraction, message)`` that shows how far long work has got.

    Parameters
    ----------
    enabled : bool, optional
        False shows nothing (``--quiet``).
    stream : file-like, optional
        Where the bar is drawn (default ``sys.stderr``).
    terminal : bool, optional
        Draw a bar (True) or log lines (False); by default a bar if ``stream`` is a terminal.
    interval_s : float, optional
        Least time between two logged lines, s.
    delay_s : float, optional
        Work shorter than this logs no line, s (default :data:`DELAY_S`).
    heartbeat_s : float or None, optional
        While a step runs without a call, the display is renewed this often, s (default
        :data:`HEARTBEAT_S`; None: never): the bar's time advances, and off a terminal the
        step is logged again every ``interval_s``, so a long step shows the work going on.

    Use it as a context manager: the bar is closed and the renewal stopped when work ends.

    Examples
    --------
    >>> with Progress(terminal=False) as progress:  # doctest: +SKIP
    ...     run_study(design, tolerances, progress=progress)
    """

    def __init__(
        self,
        enabled=True,
        stream=None,
        terminal=None,
        interval_s=10.0,
        delay_s=None,
        heartbeat_s=HEARTBEAT_S,
    ):
        self.stream = sys.stderr if stream is None else stream
        self.enabled = enabled
        self.terminal = _is_terminal(self.stream) if terminal is None else terminal
        self.interval_s = interval_s
        self.delay_s = DELAY_S if delay_s is None else delay_s
        self.heartbeat_s = heartbeat_s
        self._bar = None
        self._started = time.monotonic()
        self._logged = self._drawn = -float("inf")
        self._message = None
        self._fraction = 0.0
        self._lock = threading.Lock()
        self._stopped = threading.Event()
        self._heartbeat = None

    def __call__(self, fraction, message):
        """Show ``fraction`` (0–1, clipped; never below one shown before) of the work done and
        what is being done."""
        if not self.enabled:
            return
        with self._lock:
            fraction = max(self._fraction, _clipped(fraction))  # never backwards
            if message != self._message:  # each step, for -v
                self._message = message
                logger.debug("%s (%.1f s)", message, time.monotonic() - self._started)
            self._fraction = fraction
            self._show(fraction, message, renewal=False)
        if self._heartbeat is None and self.heartbeat_s is not None and fraction < 1.0:
            self._heartbeat = threading.Thread(target=self._beat, name="progress", daemon=True)
            self._heartbeat.start()

    def _show(self, fraction, message, renewal):
        if self.terminal:
            self._draw(fraction, message)
            return
        now = time.monotonic()
        if now - self._started < self.delay_s:
            return
        if now - self._logged >= self.interval_s or (fraction == 1.0 and not renewal):
            self._logged = now
            logger.info("%3.0f%% %s (%.0f s)", 100 * fraction, message, now - self._started)

    def _beat(self):
        """Renew the display every ``heartbeat_s`` until closed (a daemon thread)."""
        while not self._stopped.wait(self.heartbeat_s):
            with self._lock:
                if self._message is not None and self._fraction < 1.0:
                    self._show(self._fraction, self._message, renewal=True)

    def _draw(self, fraction, message):
        now = time.monotonic()
        if self._bar is not None and now - self._drawn < _REDRAW_S and fraction < 1.0:
            return
        self._drawn = now
        columns = terminal_columns(self.stream)  # at every redraw: the terminal may be resized
        ncols = columns - 1 if columns > 1 else 1  # one short of the width: never wraps
        line = _WIDE_FORMAT if columns >= _BAR_COLUMNS else _NARROW_FORMAT
        if self._bar is None:
            from tqdm import tqdm  # imported when the first bar is drawn

            self._bar = tqdm(
                total=_STEPS, file=self.stream, bar_format=line, ncols=ncols, leave=False
            )
        self._bar.ncols, self._bar.bar_format = ncols, line
        self._bar.set_description_str(message, refresh=False)
        self._bar.n = round(fraction * _STEPS)
        self._bar.refresh()

    def close(self):
        """Stop renewing the display and remove the bar, if one was drawn."""
        self._stopped.set()
        if self._heartbeat is not None and self._heartbeat is not threading.current_thread():
            self._heartbeat.join()
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False
