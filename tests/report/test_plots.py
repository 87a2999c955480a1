"""Every figure renders for the default design without warnings and carries its axis labels."""

import warnings
from dataclasses import replace

import numpy as np
import pytest
from matplotlib.figure import Figure

from reflector_opt.analysis.metrics import evaluate_metrics
from reflector_opt.calibration.segment import simulate_segment
from reflector_opt.calibration.simulation import simulate_calibration
from reflector_opt.optimise.pareto import ParetoFront, ParetoPoint
from reflector_opt.report import plots

PITCH, ROLL = "pitch γ (°)", "roll α (°)"


@pytest.fixture(scope="module")
def metrics(design):
    return evaluate_metrics(design, step_deg=1.0)


@pytest.fixture(scope="module")
def calibration(design):
    return simulate_calibration(design, "eq6", step_deg=1.0, n_validation=500)


def _labels(fig):
    """(xlabel, ylabel) of every axes that is not a colour bar, and the colour bar labels."""
    main = [(ax.get_xlabel(), ax.get_ylabel()) for ax in fig.axes if ax.get_label() != "<colorbar>"]
    bars = [ax.get_ylabel() for ax in fig.axes if ax.get_label() == "<colorbar>"]
    return main, bars


def _render(make):
    """Build and draw a figure, failing on any warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = make()
        fig.canvas.draw()
    assert isinstance(fig, Figure)
    return fig


def test_sensor_curve_shades_the_used_window(design, metrics):
    fig = _render(lambda: plots.sensor_curve_figure(design, 0, metrics))
    (labels,), _ = _labels(fig)
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
    assert plots.sensor_curve_figure(design, 1, ax=ax) is fig


def test_sensor_maps(design):
    fig = _render(lambda: plots.sensor_maps_figure(design, step_deg=1.0))
    main, bars = _labels(fig)
    assert main == [(PITCH, ROLL)] * 4
    assert sorted(bars) == ["distance d (mm)"] * 2 + ["output voltage (V)"] * 2


def test_resolution_maps_mark_the_worst_pose(design, metrics):
    fig = _render(lambda: plots.resolution_maps_figure(metrics, design))
    main, bars = _labels(fig)
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


def test_pareto_front():
    points = (
        ParetoPoint(0.0, True, worst_pitch_deg=0.10, worst_roll_deg=0.12),
        ParetoPoint(0.2, True, worst_pitch_deg=0.15, worst_roll_deg=0.16),
        ParetoPoint(0.6, False, reason="no design"),
    )
    fig = _render(lambda: plots.pareto_figure(ParetoFront(points, seed=0)))
    (labels,), _ = _labels(fig)
    assert labels == ("required distance-window margin (mm)", "worst-case 1σ resolution (°)")


def test_calibration_error_maps(calibration):
    fig = _render(lambda: plots.calibration_error_figure(calibration))
    main, bars = _labels(fig)
    assert main == [(PITCH, ROLL)] * 2
    assert bars == ["pitch error (°)", "roll error (°)"]


def test_angle_traces_report_the_rms_error():
    true = np.zeros((50, 2))
    estimate = np.column_stack([np.full(50, 0.5), np.full(50, -2.0)])
    fig = _render(lambda: plots.angle_traces_figure(true, estimate, "Fig. 5"))
    assert [ax.get_ylabel() for ax in fig.axes] == ["pitch (°)", "roll (°)"]
    assert fig.axes[-1].get_xlabel() == "sample (–)"
    assert "0.500°" in fig.axes[0].get_title() and "2.000°" in fig.axes[1].get_title()


def test_segment_estimate_against_truth(design, calibration):
    errors = simulate_segment(design, calibration.model, "roll", cycles=1, samples_per_cycle=50)
    fig = _render(lambda: plots.segment_figure(errors))
    assert [ax.get_ylabel() for ax in fig.axes] == ["tip roll (°)", "roll error (°)"]
    assert fig.axes[1].get_xlabel() == "sample (–)"


def test_tip_paths_reach_the_chain_length_when_straight(design):
    fig = _render(lambda: plots.tip_path_figure(design))
    main, _ = _labels(fig)
    assert main == [("x (mm)", "z (mm)"), ("y (mm)", "z (mm)")]
    mech = design.mechanics
    # the straight pose's chain ends at n_units × link length on the z axis
    straight = fig.axes[0].lines[-2]  # drawn last before the legend handle
    assert straight.get_ydata()[-1] == pytest.approx(mech.n_units * mech.link_length_mm)
    assert straight.get_xdata()[-1] == pytest.approx(0.0)


@pytest.mark.parametrize("plane, pose", [("xz", (15.0, 0.0)), ("yz", (0.0, -15.0))])
def test_cross_section_circle_is_the_posed_sphere(design, plane, pose):
    fig = _render(lambda: plots.cross_section_figure(design, ((0.0, 0.0), pose), plane))
    (labels,), _ = _labels(fig)
    assert labels == (f"{plane[0]} (mm)", "z (mm)")
    circle = fig.axes[0].lines[0]  # zero pose: centre (0, 0, -1.5), radius 9 in either plane
    x, z = circle.get_data()
    assert np.allclose(np.hypot(x, z + 1.5), 9.0)
    # the in-plane sensor's axis ends on the sphere: 10 − sqrt(9² − 1.5²) mm along it at 0 pose
    ray = fig.axes[0].lines[2]
    (x0, x1), (z0, z1) = ray.get_data()
    assert np.hypot(x1 - x0, z1 - z0) == pytest.approx(10.0 - np.sqrt(81.0 - 1.5**2))


def test_cross_section_rejects_an_unknown_plane(design):
    with pytest.raises(ValueError, match="plane"):
        plots.cross_section_figure(design, plane="xy")


@pytest.fixture(scope="module")
def turned(design):
    """The default design with its sensors moved to ±40° azimuth, looking at the unit's axis."""
    sensors = []
    for s, azimuth in zip(design.sensors, (40.0, -40.0), strict=True):
        c, s_ = np.cos(np.radians(azimuth)), np.sin(np.radians(azimuth))
        sensors.append(replace(s, position_mm=(10.0 * c, 10.0 * s_, 0.0), axis=(-c, -s_, 0.0)))
    return design.replace(sensors=tuple(sensors))


@pytest.mark.parametrize("sensor, azimuth", [(0, 40.0), (1, -40.0)])
def test_sensor_plane_holds_the_sensor_and_its_axis(turned, sensor, azimuth):
    normal, offset, along = plots.sensor_plane(turned, sensor)
    f, a = turned.positions_mm[sensor], turned.axes[sensor]
    assert offset == pytest.approx(0.0, abs=1e-12)  # a radial sensor: the plane holds O
    assert normal @ a == pytest.approx(0.0, abs=1e-12) and normal @ f == pytest.approx(0.0)
    assert np.degrees(np.arctan2(along[1], along[0])) == pytest.approx(azimuth)
    assert along @ f == pytest.approx(10.0)


def test_sensor_section_shows_sphere_beam_and_window(turned):
    metrics = evaluate_metrics(turned, step_deg=1.0)
    fig = _render(lambda: plots.sensor_section_figure(turned, 0, metrics))
    whole, zoom = fig.axes
    assert [(ax.get_xlabel(), ax.get_ylabel()) for ax in fig.axes] == [
        ("along azimuth 40° (mm)", "z (mm)")
    ] * 2
    lines = {line.get_label(): line for line in whole.lines}
    # zero pose: the plane through O cuts the sphere (centre 1.5 mm below O, r 9) in a great
    # circle, and the horizontal axis from 10 mm meets it at sqrt(9² − 1.5²) from the axis
    x, z = lines["sphere at pitch 0°, roll 0°"].get_data()
    assert np.allclose(np.hypot(x, z + 1.5), 9.0)
    hit = next(line for line in whole.lines if line.get_marker() == "o")
    assert hit.get_xdata()[0] == pytest.approx(np.sqrt(81.0 - 1.5**2))
    assert hit.get_ydata()[0] == pytest.approx(0.0, abs=1e-12)
    # the ruler along the axis from the sensor's face (at 10 mm): usable range and used window
    lo, hi = float(metrics.distance_min_mm[0]), float(metrics.distance_max_mm[0])
    used = lines[f"distances used {lo:.2f}–{hi:.2f} mm"].get_xdata()
    assert sorted(used) == pytest.approx([10.0 - hi, 10.0 - lo])
    usable = lines["usable range 0.5–3 mm"].get_xdata()
    assert sorted(usable) == pytest.approx([7.0, 9.5])
    names = [text.get_text() for text in zoom.get_legend().get_texts()]
    assert "beam, 1/e radius (Eq 4)" in names and "S1 (NJL5901R-2)" in names


def test_the_worst_pose_cross_lies_inside_the_axes_with_room_for_its_size(metrics, design):
    fig = _render(lambda: plots.resolution_maps_figure(metrics, design))
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


def _sweep_rows():
    rows = []
    for radius, resolution, rms in ((6.0, 0.12, 0.030), (7.0, 0.09, 0.034)):
        rows.append(
            {
                "reflector.radius_mm": radius,
                "status": "ok",
                "nominal_resolution_pitch_deg": resolution,
                "nominal_resolution_roll_deg": resolution + 0.01,
                "nominal_rms_pitch_deg": rms,
                "nominal_rms_roll_deg": rms + 0.002,
                "yield": 0.9,
            }
        )
    return rows


def test_the_sweep_shows_the_objective_and_its_legends_hide_no_data():
    fig = _render(lambda: plots.sweep_figure(_sweep_rows(), "reflector.radius_mm"))
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    top, bottom = [ax for ax in fig.axes if ax.get_legend() is not None]
    assert [t.get_text() for t in top.get_legend().get_texts()] == [
        "worst 1σ resolution, pitch",
        "worst 1σ resolution, roll",
    ]
    assert [t.get_text() for t in bottom.get_legend().get_texts()] == [
        "RMS pitch",
        "RMS roll",
        "yield",
    ]
    assert np.allclose([line.get_ydata() for line in top.lines], [[0.12, 0.09], [0.13, 0.10]])
    for ax in (top, bottom):
        legend = ax.get_legend().get_window_extent(renderer)
        for other in fig.axes:  # outside every panel (and the yield's twin)
            assert not legend.overlaps(other.get_window_extent(renderer))


def test_the_sweep_text_puts_the_objective_first():
    from reflector_opt.cli.sweep import format_table

    rows = _sweep_rows()
    for row in rows:
        row.update(nominal_window_kept=True, nominal_distance_margin_mm=0.1)
    line = format_table(rows, ["reflector.radius_mm"]).splitlines()[1]
    assert line.startswith("reflector.radius_mm=7: worst 1σ resolution pitch/roll 0.090/0.100°")
    assert "RMS pitch/roll 0.034/0.036°" in line and "yield 90.0 %" in line
