"""The 3-D previews: their tick labels do not overlap."""

import itertools

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from reflector_opt.cad._preview import space_ticks

#: Bounds (mm) of the printable variant's reflector part and body, as the previews draw them.
BOUNDS = {
    "reflector": ((-11.0, -11.0, -4.6), (11.0, 11.0, 9.3)),
    "body": ((-11.0, -11.0, -8.0), (11.0, 11.0, 2.0)),
}


def _overlapping_tick_labels(bounds, tidy):
    """Pairs of tick labels, on the same axis, whose boxes overlap in the drawn view."""
    lo, hi = np.array(bounds[0]), np.array(bounds[1])
    fig = Figure(figsize=(6.0, 5.0), dpi=110)  # as render_meshes draws
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(projection="3d")
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo)
    ax.view_init(elev=18.0, azim=40.0)
    if tidy:
        space_ticks(ax)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    pairs, shown = 0, []
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        low, high = sorted(axis.get_view_interval())
        # where the draw placed them (get_ticklabels would reset their positions)
        boxes = [
            t.label1.get_window_extent(renderer)
            for t in axis.majorTicks
            if low - 1e-9 <= t.get_loc() <= high + 1e-9
        ]
        shown.append(len(boxes))
        pairs += sum(a.overlaps(b) for a, b in itertools.combinations(boxes, 2))
    return pairs, shown


@pytest.mark.parametrize("part", sorted(BOUNDS))
def test_preview_tick_labels_do_not_overlap(part):
    before, _ = _overlapping_tick_labels(BOUNDS[part], tidy=False)
    assert before > 0  # matplotlib's default ticks do overlap: the check can fail
    after, shown = _overlapping_tick_labels(BOUNDS[part], tidy=True)
    assert after == 0
    assert min(shown) >= 2  # every axis still reads: at least two labelled ticks


def test_the_section_has_a_legend_below_the_panels_and_a_rounded_azimuth(monkeypatch, tmp_path):
    from types import SimpleNamespace

    from reflector_opt.cad import _preview as preview

    drawn = []
    monkeypatch.setattr(preview, "_save", lambda fig, path: drawn.append(fig))
    square = [np.array([[1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0]])]
    layout = SimpleNamespace(
        sphere_centre_mm=(0.0, 0.0, -2.0),
        sphere_radius_mm=7.0,
        inner_radius_mm=5.0,
        envelope_radius_mm=11.0,
        body_bottom_z_mm=-8.0,
        flange_top_z_mm=9.0,
    )
    sections = [{"sensors": square, "body": square, "reflector": []}]
    preview.render_section(tmp_path / "s.png", sections, layout, [-42.0225])
    (fig,) = drawn
    (ax,) = fig.axes
    assert ax.get_xlabel() == "distance along azimuth -42.0° (mm)"
    (legend,) = fig.legends
    texts = [t.get_text() for t in legend.get_texts()]
    assert texts[:2] == [preview.LABELS["sensors"], preview.LABELS["body"]]  # the red block
    assert preview.LABELS["reflector"] not in texts  # not drawn in this section
    canvas = FigureCanvasAgg(fig)  # as _save draws it
    canvas.draw()
    renderer = canvas.get_renderer()
    assert not legend.get_window_extent(renderer).overlaps(ax.get_window_extent(renderer))
