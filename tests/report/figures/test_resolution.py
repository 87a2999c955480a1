"""The resolution maps: labels, the worst pose marked and inside the axes."""

import numpy as np

from reflector_opt.report.figures._resolution import resolution_maps_figure
from tests.report.figures.drawing import PITCH, ROLL, axis_labels, render


def test_resolution_maps_mark_the_worst_pose(design, metrics):
    fig = render(lambda: resolution_maps_figure(metrics, design))
    main, bars = axis_labels(fig)
    assert main == [(PITCH, ROLL)] * 3
    assert set(bars) == {
        "1σ pitch resolution (°)",
        "1σ roll resolution (°)",
        "condition number of J (–)",
    }
    pitch, roll = design.workspace.axes(1.0)
    i, j = np.unravel_index(np.argmax(metrics.resolution_pitch_deg), metrics.condition.shape)
    marker = next(line for line in fig.axes[0].lines if line.get_label() == "worst")
    assert marker.get_xdata()[0] == pitch[i] and marker.get_ydata()[0] == roll[j]


def test_the_worst_pose_cross_lies_inside_the_axes_with_room_for_its_size(metrics, design):
    fig = render(lambda: resolution_maps_figure(metrics, design))
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    maps = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    for ax in maps:
        (marker,) = [line for line in ax.lines if line.get_label() == "worst"]
        x, y = marker.get_xdata()[0], marker.get_ydata()[0]
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        assert x0 < x < x1 and y0 < y < y1
        box = ax.get_window_extent(renderer)
        px, py = ax.transData.transform((x, y))
        half = marker.get_markersize() * fig.dpi / 72 / 2
        assert box.x0 + half <= px <= box.x1 - half and box.y0 + half <= py <= box.y1 - half
        assert ax.get_legend() is None and "(red ×)" in ax.get_title()
