"""Progress: a tqdm bar on a terminal, plain periodic log lines elsewhere, nothing when off."""

import io
import logging
import os
import time

import pytest

from reflector_opt.util._progress import (
    FALLBACK_COLUMNS,
    Phases,
    Progress,
    monotone,
    no_progress,
    scaled,
    terminal_columns,
)

LOGGER = "reflector_opt.util._progress"


class _Tty(io.StringIO):
    def isatty(self):
        return True


def test_off_shows_and_logs_nothing(caplog):
    caplog.set_level(logging.DEBUG, logger=LOGGER)
    for stream in (io.StringIO(), _Tty()):
        with Progress(enabled=False, stream=stream) as progress:
            progress(0.5, "hidden")
        assert stream.getvalue() == ""
    assert caplog.records == []
    assert no_progress(0.5, "nothing") is None


def test_a_terminal_gets_a_bar_that_is_cleared_at_the_end(caplog, monkeypatch):
    caplog.set_level(logging.DEBUG, logger=LOGGER)
    monkeypatch.setenv("COLUMNS", "80")
    tty = _Tty()
    with Progress(stream=tty) as progress:
        assert progress.terminal
        progress(0.25, "a quarter")
        progress(1.7, "done")  # clipped to 100 %
    text = tty.getvalue()
    assert " 25%|" in text and "a quarter" in text
    assert "100%|" in text and "done" in text and "170%" not in text
    assert text.endswith("\r")  # the bar is removed (tqdm's leave=False)
    assert all(r.levelno == logging.DEBUG for r in caplog.records)  # a bar, not log lines


def test_elsewhere_plain_lines_at_the_start_periodically_and_at_the_end(caplog):
    caplog.set_level(logging.INFO, logger=LOGGER)
    log = io.StringIO()
    with Progress(stream=log, interval_s=3600.0, delay_s=0.0) as progress:
        assert not progress.terminal
        progress(0.0, "starting")
        progress(0.4, "too soon to log again")
        progress(-1.0, "clipped to 0")
        progress(1.0, "finished")
    assert log.getvalue() == ""  # nothing drawn, no control characters
    messages = [r.getMessage() for r in caplog.records]
    assert len(messages) == 2
    assert messages[0].startswith("  0% starting (")
    assert messages[1].startswith("100% finished (") and messages[1].endswith(" s)")

    caplog.clear()
    with Progress(stream=log, interval_s=0.0, delay_s=0.0, heartbeat_s=None) as progress:
        for i in range(4):
            progress(i / 4, f"step {i}")
    assert [r.getMessage().split(" (")[0] for r in caplog.records] == [
        "  0% step 0",
        " 25% step 1",
        " 50% step 2",
        " 75% step 3",
    ]


def test_quick_work_logs_no_line_so_an_early_error_stands_alone(caplog, monkeypatch):
    caplog.set_level(logging.INFO, logger=LOGGER)
    now = [100.0]
    monkeypatch.setattr("reflector_opt.util._progress.time.monotonic", lambda: now[0])
    quick = ((0.5, 0.0, "building"), (1.0, 1.0, "done early"))  # not even its end logged
    long = ((0.5, 0.0, "building"), (2.5, 0.5, "still going"), (3.0, 1.0, "finished"))
    for steps in (quick, long):  # long work: logged after the delay, and its end
        now[0] = 100.0
        with Progress(stream=io.StringIO(), interval_s=3600.0, delay_s=2.0) as progress:
            for seconds, fraction, message in steps:
                now[0] = 100.0 + seconds
                progress(fraction, message)
    assert [r.getMessage().split(" (")[0] for r in caplog.records] == [
        " 50% still going",
        "100% finished",
    ]


def test_a_failure_inside_still_closes_the_bar():
    tty = _Tty()
    with pytest.raises(RuntimeError), Progress(stream=tty) as progress:
        progress(0.5, "half")
        raise RuntimeError("stop")
    assert progress._bar is None and tty.getvalue().endswith("\r")


def test_each_new_step_is_logged_at_debug_level(caplog):
    caplog.set_level(logging.DEBUG, logger=LOGGER)
    with Progress(stream=io.StringIO(), interval_s=3600.0, delay_s=0.0) as progress:
        progress(0.0, "search")
        progress(0.5, "search")
        progress(0.6, "polish")
    debug = [r.getMessage() for r in caplog.records if r.levelno == logging.DEBUG]
    assert [m.split(" (")[0] for m in debug] == ["search", "polish"]
    assert all(m.endswith(" s)") for m in debug)
    info = [r.getMessage() for r in caplog.records if r.levelno == logging.INFO]
    assert len(info) == 1 and info[0].startswith("  0% search")


def _segments(text):
    """What each carriage return leaves on the line (ANSI-free: tqdm writes none here)."""
    return [part for part in text.split("\r") if part.strip()]


@pytest.mark.parametrize("reported", [0, None], ids=["zero columns", "no size at all"])
def test_a_terminal_without_a_width_still_shows_progress(monkeypatch, reported):
    def size(fd):
        if reported is None:
            raise OSError("not a terminal")
        return os.terminal_size((reported, 0))

    monkeypatch.setattr("reflector_opt.util._progress.os.get_terminal_size", size)
    monkeypatch.setenv("COLUMNS", "0")  # as some containers set it: no override
    assert terminal_columns(_Tty()) == FALLBACK_COLUMNS
    tty = _Tty()
    with Progress(stream=tty) as progress:
        progress(0.3, "fitting unit 2 of 3")
    lines = _segments(tty.getvalue())
    assert any(" 30%" in line and "fitting unit 2 of 3" in line for line in lines)
    assert all(len(line) < FALLBACK_COLUMNS for line in lines)


@pytest.mark.parametrize("columns", [1, 12, 40, 59, 60, 200])
def test_the_line_fits_any_width_and_keeps_the_percentage(monkeypatch, columns):
    monkeypatch.setenv("COLUMNS", str(columns))
    assert terminal_columns(_Tty()) == columns
    tty = _Tty()
    with Progress(stream=tty) as progress:
        progress(0.5, "a step with a rather long description of what is being done")
        progress(1.0, "done")
    lines = _segments(tty.getvalue())
    assert lines and all(len(line) <= max(columns - 1, 1) for line in lines)  # never wraps
    if columns >= 12:
        assert any(line.startswith(" 50%") for line in lines)
        assert any(line.startswith("100%") for line in lines)
    assert any("|" in line for line in lines) == (columns >= 60)  # a bar only where it fits


def test_the_line_follows_a_resized_terminal(monkeypatch):
    tty = _Tty()
    monkeypatch.setenv("COLUMNS", "100")
    with Progress(stream=tty) as progress:
        progress(0.2, "wide")
        monkeypatch.setenv("COLUMNS", "20")
        progress._drawn = -float("inf")  # past the redraw interval
        progress(0.4, "narrow")
    lines = _segments(tty.getvalue())
    assert any("wide" in line and len(line) > 20 for line in lines)
    assert any("narrow" in line and len(line.rstrip()) < 20 for line in lines)


def test_off_a_terminal_a_long_run_gives_few_plain_lines(caplog, monkeypatch):
    """Piped: one line per interval, not one per call, and no carriage return anywhere."""
    caplog.set_level(logging.INFO, logger=LOGGER)
    now = [0.0]
    monkeypatch.setattr("reflector_opt.util._progress.time.monotonic", lambda: now[0])
    log = io.StringIO()
    with Progress(stream=log, interval_s=10.0, delay_s=2.0) as progress:
        for i in range(601):  # a call every 0.1 s for a minute
            now[0] = 0.1 * i
            progress(i / 600, "working")
    messages = [r.getMessage() for r in caplog.records]
    assert 5 <= len(messages) <= 8 and messages[-1].startswith("100% working")
    assert log.getvalue() == "" and not any("\r" in m for m in messages)


def test_a_long_step_without_reports_still_shows_the_work_going_on(caplog):
    """Off a terminal the step is logged again every interval; on one the bar is redrawn
    (its elapsed time advancing); nothing once the display is closed."""
    caplog.set_level(logging.INFO, logger=LOGGER)
    with Progress(stream=io.StringIO(), interval_s=0.05, delay_s=0.0, heartbeat_s=0.01) as p:
        p(0.3, "one long step")
        time.sleep(0.3)
    lines = [r.getMessage() for r in caplog.records]
    assert len(lines) >= 3 and all(line.startswith(" 30% one long step (") for line in lines)
    time.sleep(0.1)
    assert len(caplog.records) == len(lines)  # the renewal stopped with the display
    assert not p._heartbeat.is_alive()

    tty = _Tty()
    with Progress(stream=tty, heartbeat_s=0.15) as p:
        p(0.5, "drawing")
        time.sleep(0.6)
    assert tty.getvalue().count("drawing") >= 3


def test_a_progress_never_shows_less_than_before(caplog):
    caplog.set_level(logging.INFO, logger=LOGGER)
    with Progress(stream=io.StringIO(), terminal=False, interval_s=0, delay_s=0) as progress:
        for fraction in (0.2, 1.0, 0.24, 0.5):  # optimise once went from 100 % to 24 %
            progress(fraction, "step")
    assert [r.getMessage().split("%")[0].strip() for r in caplog.records] == ["20"] + ["100"] * 3


def test_phases_share_the_display_by_their_work():
    shown = []
    phases = Phases(lambda f, m: shown.append((round(f, 6), m)), {"a": 1.0, "b": 0.0, "c": 3.0})
    phases("a")(0.5, "half of a")  # 1/4 of the work is a's: half of it is 1/8
    phases("b")(0.3, "b takes no time")
    phases("c")(-1.0, "clipped to c's start")
    phases("c")(2.0 / 3.0, "two thirds of c")
    phases("a")(1.0, "a late report")  # never backwards
    phases.finish("done")
    assert shown == [
        (0.125, "half of a"),
        (0.25, "b takes no time"),
        (0.25, "clipped to c's start"),
        (0.75, "two thirds of c"),
        (0.75, "a late report"),
        (1.0, "done"),
    ]


def test_scaled_phases_nest_and_monotone_is_idempotent():
    shown = []
    whole = monotone(lambda f, m: shown.append(f))
    assert monotone(whole) is whole
    inner = scaled(scaled(whole, 0.5, 1.0), 0.0, 0.5)  # the first half of the second half
    inner(0.5, "x")
    inner(1.5, "y")  # clipped
    assert shown == [0.625, 0.75]
    assert monotone(None) is not None  # None shows nothing
