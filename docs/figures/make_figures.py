"""Regenerate the user guide's figures from the package's plot functions.

Run from the repository root:  PYTHONPATH=. python docs/figures/make_figures.py
"""

from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import reflector_opt as ro
from reflector_opt.report.plots import cross_section_figure, save_figure, sensor_curve_figure

HERE = Path(__file__).resolve().parent


def frame_figure(design):
    """The two sections of the default design: pitch in the x–z plane, roll in the y–z plane."""
    fig = Figure(figsize=(11.0, 5.5), layout="constrained")
    FigureCanvasAgg(fig)
    left, right = fig.subplots(1, 2)
    cross_section_figure(design, ((0.0, 0.0), (15.0, 0.0)), "xz", ax=left)
    left.set_title("pitch γ about y: +15° moves the centre C towards −x")
    cross_section_figure(design, ((0.0, 0.0), (0.0, 15.0)), "yz", ax=right)
    right.set_title("roll α about x: +15° moves the centre C towards +y")
    return fig


def main():
    design = ro.default_design()
    save_figure(frame_figure(design), HERE / "frame-conventions.png", dpi=100)
    save_figure(sensor_curve_figure(design), HERE / "sensor-curve.png", dpi=100)


if __name__ == "__main__":
    main()
