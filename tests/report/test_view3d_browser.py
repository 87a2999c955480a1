"""The 3D view in a real browser (Debian's Chromium driven by playwright, no browser download):
the page and the report's section load with no console error and no request but the file's
own, the parts are drawn, and a slider turns the reflector to the pose whose Eq 3 distances
the page then shows.

``.ci/run`` installs Chromium where it is missing and apt-get can; the tests are skipped,
with the reason, only where no Chromium can be had.
"""

import io
import shutil
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose
from PIL import Image
from playwright.sync_api import sync_playwright

from reflector_opt.cad._solids import pose_matrix
from reflector_opt.design import load_design
from reflector_opt.report._render import render_html
from reflector_opt.report._view3d import view_blocks, write_view
from tests.report.test_view3d import SAMPLE, _hand_eq3

#: Chromium's flags: headless, and nothing that reaches out on its own.
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def _chromium():
    found = [shutil.which(n) for n in ("chromium", "chromium-browser")] + ["/usr/bin/chromium"]
    return next((p for p in found if p and Path(p).is_file()), None)


CHROMIUM = _chromium()
pytestmark = pytest.mark.skipif(
    CHROMIUM is None,
    reason="no Chromium here (.ci/run installs Debian's chromium where apt-get can)",
)


@pytest.fixture(scope="module")
def browser():
    """One headless Chromium for the module (playwright gives it a fresh profile)."""
    with sync_playwright() as playwright:
        chromium = playwright.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
        yield chromium
        chromium.close()


@pytest.fixture(scope="module")
def pages(tmp_path_factory):
    """The view alone (as export writes it) and the report's section in the report's page."""
    design = load_design(SAMPLE)
    folder = tmp_path_factory.mktemp("view3d")
    alone = write_view(design, folder)
    in_report = folder / "report.html"
    in_report.write_text(render_html([("h1", "report"), *view_blocks(design)]), encoding="utf-8")
    return design, {"view": alone, "report": in_report}


def _open(browser, path):
    """Load a page; every request is recorded and all but the page's own are refused."""
    page = browser.new_page(viewport={"width": 1000, "height": 1000})
    errors, requests = [], []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.on("request", lambda r: requests.append(r.url))
    own = path.as_uri()
    page.route("**/*", lambda r: r.continue_() if r.request.url == own else r.abort())
    page.goto(own)
    page.wait_for_load_state("load")
    return page, errors, requests


def _canvas(page):
    png = page.locator(".view3d canvas").screenshot()
    image = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
    return image[2:-2, 2:-2]  # inside the canvas's border


def _drawn(image):
    """Where the canvas is not its white background."""
    return (image < 245).any(axis=-1)


def _middle(mask):
    h, w = mask.shape
    return mask[int(0.3 * h) : int(0.7 * h), int(0.35 * w) : int(0.65 * w)]


@pytest.mark.parametrize("which", ["view", "report"])
def test_page_loads_alone_and_draws_the_parts(browser, pages, which):
    _, paths = pages
    page, errors, requests = _open(browser, paths[which])
    try:
        image = _canvas(page)
        assert errors == [] and requests == [paths[which].as_uri()]
        drawn = _drawn(image)
        assert _middle(drawn).mean() > 0.5  # the parts stand about O, the canvas's middle
        h = drawn.shape[0]
        assert not drawn[: h // 20].any() and not drawn[-h // 20 :].any()  # and fit in it
        assert page.inner_text(".view3d-readout").startswith("pitch 0.0°, roll 0.0°")
    finally:
        page.close()


def test_a_slider_turns_the_reflector_to_the_models_pose(browser, pages):
    design, paths = pages
    page, errors, _ = _open(browser, paths["view"])
    try:
        before = _canvas(page)
        page.locator("input[name=pitch]").fill("30")  # the last value: 15°
        page.locator("input[name=roll]").fill("7")  # -15° + 7 × 1°
        after = _canvas(page)
        pose = page.evaluate("document.querySelector('.view3d').view3d.pose()")
        readout = page.inner_text(".view3d-readout")
        assert errors == []
    finally:
        page.close()
    assert (pose["pitch_deg"], pose["roll_deg"]) == (15.0, -8.0)
    assert_allclose(pose["rotation"], pose_matrix(15.0, -8.0)[:, :3], atol=1e-12)
    changed = (np.abs(after - before).sum(axis=-1) > 30) & (_drawn(before) | _drawn(after))
    assert _middle(changed).mean() > 0.1  # the reflector part moved (held still: 0.7 %)
    distance, _, _ = _hand_eq3(design, 15.0, -8.0)
    assert readout.startswith("pitch 15.0°, roll -8.0°")
    for sensor, d in zip(design.sensors, distance, strict=True):
        assert f"{sensor.name}: d = {d:.3f} mm" in readout
