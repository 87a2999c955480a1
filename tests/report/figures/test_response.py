"""The sensors' response figures: the voltage curve with its window, the distance and
voltage maps."""

import numpy as np
import pytest
from matplotlib.figure import Figure

from reflector_opt.report.figures._response import sensor_curve_figure, sensor_maps_figure
from tests.report.figures.drawing import PITCH, ROLL, axis_labels, render


def test_sensor_curve_shades_the_used_window(design, metrics):
    fig = render(lambda: sensor_curve_figure(design, 0, metrics))
    (labels,), _ = axis_labels(fig)
    assert labels == ("distance to reflector d (mm)", "output voltage (V)")
    ax = fig.axes[0]
    span = ax.patches[0]  # the shaded window, a rectangle in data x
    assert span.get_x() == pytest.approx(metrics.distance_min_mm[0])
    assert span.get_x() + span.get_width() == pytest.approx(metrics.distance_max_mm[0])
    # the curve is the flat-target model through the electronics
    model = design.models[0]
    d, v = ax.lines[0].get_data()
    assert np.allclose(v, model.output_voltage(model.flat_coupling(d, 0.9)))


def test_sensor_curve_into_given_axes_without_metrics(design):
    fig = Figure()
    ax = fig.add_subplot()
    assert sensor_curve_figure(design, 1, ax=ax) is fig


def test_sensor_maps(design):
    fig = render(lambda: sensor_maps_figure(design, step_deg=1.0))
    main, bars = axis_labels(fig)
    assert main == [(PITCH, ROLL)] * 4
    assert sorted(bars) == ["distance d (mm)"] * 2 + ["output voltage (V)"] * 2
