"""The Pareto front and the sweep figures."""

import numpy as np

from reflector_opt.optimiser._pareto import ParetoFront, ParetoPoint
from reflector_opt.report.figures._optimiser import pareto_figure, sweep_figure
from tests.report.figures.drawing import axis_labels, render


def test_pareto_front():
    points = (
        ParetoPoint(0.0, True, worst_pitch_deg=0.10, worst_roll_deg=0.12),
        ParetoPoint(0.2, True, worst_pitch_deg=0.15, worst_roll_deg=0.16),
        ParetoPoint(0.6, False, reason="no design"),
    )
    fig = render(lambda: pareto_figure(ParetoFront(points, seed=0)))
    (labels,), _ = axis_labels(fig)
    assert labels == ("required distance-window margin (mm)", "worst-case 1σ resolution (°)")


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
    fig = render(lambda: sweep_figure(_sweep_rows(), "reflector.radius_mm"))
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
    from reflector_opt.workflow._tolerance_text import format_table

    rows = _sweep_rows()
    for row in rows:
        row.update(nominal_window_kept=True, nominal_distance_margin_mm=0.1)
    line = format_table(rows, ["reflector.radius_mm"]).splitlines()[1]
    assert line.startswith("reflector.radius_mm=7: white-noise worst 1σ pitch/roll 0.090/0.100°")
    assert "RMS pitch/roll 0.034/0.036°" in line and "yield 90.0 %" in line
    # with the in-use worst case (sweep --conditions, or the default ones) it comes first
    rows[1]["nominal_worst_case_deg"] = 1.25
    line = format_table(rows, ["reflector.radius_mm"]).splitlines()[1]
    assert line.startswith("reflector.radius_mm=7: in-use worst case 1.250°, white-noise worst")
