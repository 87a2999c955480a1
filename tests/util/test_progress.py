"""Progress: a tqdm bar on a terminal, plain periodic log lines elsewhere, nothing when off."""

import io
import logging

import pytest

from reflector_opt.util.progress import Progress, no_progress

LOGGER = "reflector_opt.util.progress"


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


def test_a_terminal_gets_a_bar_that_is_cleared_at_the_end(caplog):
    caplog.set_level(logging.DEBUG, logger=LOGGER)
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
    with Progress(stream=log, interval_s=0.0, delay_s=0.0) as progress:
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
    monkeypatch.setattr("reflector_opt.util.progress.time.monotonic", lambda: now[0])
    with Progress(stream=io.StringIO(), interval_s=3600.0, delay_s=2.0) as progress:
        for seconds, fraction, message in (
            (0.5, 0.0, "building"),  # too early
            (1.0, 1.0, "done early"),  # even the end of quick work is not logged
            (2.5, 0.5, "still going"),  # long work: logged
            (3.0, 1.0, "finished"),  # and its end
        ):
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
