"""The live view in a real browser (Debian's Chromium driven by playwright, as
tests/report/test_view3d_browser.py does, and skipped by the same rule): the virtual device holds
one pose, then bends to another; ``stream --view`` serves the page, the page connects, and the
segment it draws follows, read back from its script (the angles, the last unit's posed frame and
the tip it drew, against the stream's own CSV) and as pixels (the canvas at the two poses).
The same run with a page that ignores the WebSocket's messages fails both checks.
"""

import csv
import logging
import re
import threading

import numpy as np
import pytest
from numpy.testing import assert_allclose
from playwright.sync_api import TimeoutError as PageTimeout

from reflector_opt.calibration._segment import tip_pose
from reflector_opt.robot import Protocol, VirtualDevice
from reflector_opt.workflow._stream import stream
from tests.report.test_view3d import SAMPLE
from tests.report.test_view3d_browser import (  # noqa: F401 (browser: a fixture)
    CHROMIUM,
    _canvas,
    _drawn,
    browser,
)
from tests.robot.test_live import _hand_rotation
from tests.robot.test_stream_run import LINK_MM, coefficients  # noqa: F401 (a fixture)
from tests.robot.test_virtual import RATE_HZ, FakeClock, truth

pytestmark = pytest.mark.skipif(
    CHROMIUM is None,
    reason="no Chromium here (.ci/run installs Debian's chromium where apt-get can)",
)

#: The device's two poses, (pitch, roll) per unit, degrees: straight, then bent 12° in pitch
#: with the roll growing along the segment.
POSES = (np.zeros((3, 2)), np.array([[12.0, 0.0], [12.0, -3.0], [12.0, -6.0]]))
#: Frames at each pose; the page is checked against the last of each (counters 49 and 99).
HELD = 50

VIEW = "document.querySelector('.view3d').view3d.pose()"


def _frames():
    """The virtual device's frames of the truth: HELD at the first pose, HELD at the second."""
    clock = FakeClock()
    device = VirtualDevice(
        Protocol(3),
        truth,
        lambda t: POSES[int(t * RATE_HZ + 1e-9) >= HELD],
        RATE_HZ,
        clock=clock,
        sleep=clock.sleep,
    )
    frames = []
    device.run(frames.append, 2 * HELD)
    return [b"".join(frames[:HELD]), b"".join(frames[HELD:])]


def _live(browser, coefficients, tmp_path, caplog, ignore=False):  # noqa: F811
    """Stream the two poses with ``--view``; at each, once the browser has received its last
    frame's message, the page's state and the canvas. ``ignore``: the page's WebSocket drops
    every message (as a page ignoring the updates would)."""
    chunks, go = _frames(), [threading.Event(), threading.Event()]

    def link():  # the device: a pose, held until the page was looked at
        for chunk, proceed in zip(chunks, go, strict=True):
            yield chunk
            proceed.wait(120)

    caplog.set_level(logging.INFO, logger="reflector_opt")
    out, result = tmp_path / "angles.csv", {}
    options = dict(view="127.0.0.1:0", design=str(SAMPLE), link_length_mm=LINK_MM)
    streaming = threading.Thread(
        target=lambda: result.update(run=stream(link(), coefficients, **options).write(out))
    )
    streaming.start()
    page = browser.new_page(viewport={"width": 1000, "height": 1000})
    try:
        url = None
        for _ in range(1200):  # the page is built (the design's solids), then served
            if url := re.search(r"live view: (http://\S+/)", caplog.text):
                break
            page.wait_for_timeout(100)
        errors, received = [], []
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.on("websocket", lambda ws: ws.on("framereceived", lambda m: received.append(m)))
        if ignore:
            page.add_init_script(
                "Object.defineProperty(WebSocket.prototype, 'onmessage', {set() {}})"
            )
        page.goto(url.group(1))
        seen = []
        for counter, proceed in zip((HELD - 1, 2 * HELD - 1), go, strict=True):
            for _ in range(200):  # the browser's socket has the pose's last message
                if any(f'"counter": "{counter}"' in str(m) for m in received):
                    break
                page.wait_for_timeout(50)
            try:
                page.wait_for_function(f"{VIEW}.counter === '{counter}'", timeout=3000)
            except PageTimeout:
                pass  # not drawn: the checks below fail
            seen.append((page.evaluate(VIEW), _canvas(page)))
            proceed.set()
    finally:
        for proceed in go:
            proceed.set()
        streaming.join()
        page.close()
    with open(out, newline="") as handle:
        rows = {r["counter"]: r for r in csv.DictReader(handle)}
    return seen, rows, errors


def _follows(state, row):
    """Whether the page drew the CSV's row: its angles, the last unit's frame R_1⋯R_n (by hand
    from those angles), and the tip (the stream's tip_pose) within 1e-9 mm."""
    angles = np.array([[float(row[f"{j}_{a}_deg"]) for a in ("pitch", "roll")] for j in "123"])
    frame = np.linalg.multi_dot([_hand_rotation(*a) for a in angles])
    tip = [float(row[f"tip_{x}_mm"]) for x in "xyz"]
    return (
        state["counter"] == row["counter"]
        and np.allclose(state["angles_deg"], angles, rtol=0, atol=1e-12)
        and np.allclose(state["rotation"], frame, rtol=0, atol=1e-12)
        and np.allclose(state["tip_mm"], tip, rtol=0, atol=1e-9)
    )


def _moved(before, after):
    """The share of the drawn pixels (at either pose) that changed."""
    drawn = _drawn(before) | _drawn(after)
    return ((np.abs(after - before).sum(axis=-1) > 30) & drawn).sum() / drawn.sum()


def test_the_drawn_segment_follows_the_virtual_device(browser, coefficients, tmp_path, caplog):  # noqa: F811
    """At each pose the page's script holds the stream's newest angles, the last unit's frame
    and the tip (1e-9 mm), the tip within 0.5 mm of the device's true one; from the first pose
    to the second the tip moves 22 mm and over a fifth of the drawn pixels change (three
    quarters here)."""
    seen, rows, errors = _live(browser, coefficients, tmp_path, caplog)
    assert errors == []
    for (state, _), pose, counter in zip(seen, POSES, ("49", "99"), strict=True):
        assert _follows(state, rows[counter])
        _, true_tip = tip_pose(pose[:, 0], pose[:, 1], LINK_MM)
        assert_allclose(state["tip_mm"], true_tip, rtol=0, atol=0.5)
    (straight, before), (bent, after) = seen
    assert np.linalg.norm(np.subtract(bent["tip_mm"], straight["tip_mm"])) > 15
    assert _moved(before, after) > 0.2


def test_a_page_that_ignores_the_updates_fails_the_checks(browser, coefficients, tmp_path, caplog):  # noqa: F811
    """The messages reach the browser but the page drops them: it still draws the straight
    chain it starts with, so neither pose's row is followed and no pixel moves."""
    seen, rows, _ = _live(browser, coefficients, tmp_path, caplog, ignore=True)
    assert not any(
        _follows(state, rows[c]) for (state, _), c in zip(seen, ("49", "99"), strict=True)
    )
    assert seen[0][0]["counter"] is None and _moved(seen[0][1], seen[1][1]) == 0
