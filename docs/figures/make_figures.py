"""Regenerate the documentation's figures: the user guide's from the package's plot
functions, and the layer diagram of docs/architecture.md.

Run from the repository root:  PYTHONPATH=. python docs/figures/make_figures.py
"""

from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import FancyBboxPatch

import reflector_opt as ro
from reflector_opt.report.figures._base import save_figure
from reflector_opt.report.figures._response import sensor_curve_figure
from reflector_opt.report.figures._sections import cross_section_figure, sensor_section_figure

HERE = Path(__file__).resolve().parent

#: The package's layers, top to bottom (tests/test_architecture.py holds the order), and what
#: each owns in a few words; the second column names a group of layers, or is empty.
LAYERS = (
    ("cli", "interface", "the reflector-opt command: parse, call the library, print"),
    ("workflow", "interface", "whole runs in one call: optimise, evaluate, report"),
    ("report", "output", "the design report (blocks, Jinja templates) and its figures"),
    ("cad", "output", "printable parts (STL, 3MF), printability, ray checks"),
    ("optimiser", "", "variables, objective, search; studies over one driver"),
    ("asbuilt", "", "as-built identification, AS_BUILT.json, correction of the next print"),
    ("tolerance", "", "built units, predicted errors, Monte Carlo yield, Sobol, sweeps"),
    ("robot", "", "device frames and links, live angles, MCAP, record, C99 firmware"),
    ("calibration", "", "Eq 5/6 models, fits, protocol, segment, pose plans"),
    ("analysis", "", "window, Jacobian, Cramér–Rao resolution, uniqueness"),
    ("design", "", "the Design, design.json, validation, parts, layout"),
    ("model", "", "Eq 1–4: geometry, optics, kernel, sensors, noise"),
    ("util", "", "errors, atomic file output, worker pools, progress"),
)


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


def architecture_figure():
    """The layers stacked top to bottom, an arrow down from each to the one it may import."""
    fig = Figure(figsize=(7.0, 7.2), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    step, height, left, width = 1.0, 0.62, 0.0, 7.6
    top = step * (len(LAYERS) - 1)
    for row, (name, _, owns) in enumerate(LAYERS):
        y = top - row * step
        ax.add_patch(
            FancyBboxPatch(
                (left, y - height / 2),
                width,
                height,
                boxstyle="round,pad=0,rounding_size=0.12",
                facecolor="#dde8f3"
                if name not in ("cad", "report", "workflow", "cli")
                else "#f3e6d3",
                edgecolor="#33506e",
                linewidth=1.0,
            )
        )
        ax.text(left + 0.2, y, name, va="center", ha="left", fontsize=11, fontweight="bold")
        ax.text(left + 1.75, y, owns, va="center", ha="left", fontsize=9.5)
        if row < len(LAYERS) - 1:
            ax.annotate(
                "",
                xy=(left + 0.75, y - step + height / 2),
                xytext=(left + 0.75, y - height / 2),
                arrowprops={"arrowstyle": "-|>", "color": "#33506e", "lw": 1.2},
            )
    for group in ("interface", "output"):
        rows = [row for row, layer in enumerate(LAYERS) if layer[1] == group]
        high, low = top - rows[0] * step + height / 2, top - rows[-1] * step - height / 2
        x = left + width + 0.15
        ax.plot([x, x + 0.1, x + 0.1, x], [high, high, low, low], color="0.35", lw=1.0)
        ax.text(x + 0.2, (high + low) / 2, group, va="center", ha="left", fontsize=9.5)
    ax.text(
        left,
        -0.75,
        "An arrow: may import the layer below, and so every layer below that.\n"
        "A module may import its own layer and those below it, never one above.",
        va="top",
        ha="left",
        fontsize=9,
        color="0.25",
    )
    ax.set_xlim(left - 0.1, left + width + 1.25)
    ax.set_ylim(-1.5, top + 0.45)
    ax.set_axis_off()
    return fig


def main():
    design = ro.default_design()
    save_figure(frame_figure(design), HERE / "frame-conventions.png", dpi=100)
    save_figure(sensor_curve_figure(design), HERE / "sensor-curve.png", dpi=100)
    save_figure(sensor_section_figure(design, 0), HERE / "sensor-section.png", dpi=100)
    save_figure(architecture_figure(), HERE / "architecture.png", dpi=100)


if __name__ == "__main__":
    main()
