"""The sections: the posed sphere in the x–z and y–z planes, and one sensor's own plane."""

import numpy as np
import pytest

from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.report.figures._sections import cross_section_figure, sensor_section_figure
from tests.report.figures.drawing import axis_labels, render


@pytest.mark.parametrize("plane, pose", [("xz", (15.0, 0.0)), ("yz", (0.0, -15.0))])
def test_cross_section_circle_is_the_posed_sphere(design, plane, pose):
    fig = render(lambda: cross_section_figure(design, ((0.0, 0.0), pose), plane))
    (labels,), _ = axis_labels(fig)
    assert labels == (f"{plane[0]} (mm)", "z (mm)")
    circle = fig.axes[0].lines[0]  # zero pose: centre (0, 0, -1.4), radius 9 in either plane
    x, z = circle.get_data()
    assert np.allclose(np.hypot(x, z + 1.4), 9.0)
    # the in-plane sensor's axis ends on the sphere: 10 − sqrt(9² − 1.4²) mm along it at 0 pose
    ray = fig.axes[0].lines[2]
    (x0, x1), (z0, z1) = ray.get_data()
    assert np.hypot(x1 - x0, z1 - z0) == pytest.approx(10.0 - np.sqrt(81.0 - 1.4**2))


def test_cross_section_rejects_an_unknown_plane(design):
    with pytest.raises(ValueError, match="plane"):
        cross_section_figure(design, plane="xy")


def test_sensor_section_shows_sphere_beam_and_window(turned):
    metrics = evaluate_metrics(turned, step_deg=1.0)
    fig = render(lambda: sensor_section_figure(turned, 0, metrics))
    whole, zoom = fig.axes
    assert [(ax.get_xlabel(), ax.get_ylabel()) for ax in fig.axes] == [
        ("along azimuth 40° (mm)", "z (mm)")
    ] * 2
    lines = {line.get_label(): line for line in whole.lines}
    # zero pose: the plane through O cuts the sphere (centre 1.4 mm below O, r 9) in a great
    # circle, and the horizontal axis from 10 mm meets it at sqrt(9² − 1.4²) from the axis
    x, z = lines["sphere at pitch 0°, roll 0°"].get_data()
    assert np.allclose(np.hypot(x, z + 1.4), 9.0)
    hit = next(line for line in whole.lines if line.get_marker() == "o")
    assert hit.get_xdata()[0] == pytest.approx(np.sqrt(81.0 - 1.4**2))
    assert hit.get_ydata()[0] == pytest.approx(0.0, abs=1e-12)
    # the ruler along the axis from the sensor's face (at 10 mm): usable range and used window
    lo, hi = float(metrics.distance_min_mm[0]), float(metrics.distance_max_mm[0])
    used = lines[f"distances used {lo:.2f}–{hi:.2f} mm"].get_xdata()
    assert sorted(used) == pytest.approx([10.0 - hi, 10.0 - lo])
    usable = lines["usable range 0.5–3 mm"].get_xdata()
    assert sorted(usable) == pytest.approx([7.0, 9.5])
    names = [text.get_text() for text in zoom.get_legend().get_texts()]
    assert "beam, 1/e radius (Eq 4)" in names and "S1 (NJL5901R-2)" in names
