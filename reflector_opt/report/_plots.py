"""Every figure in one namespace, for scripts and notebooks (``from reflector_opt.report import
plots``). The figures live by domain in :mod:`reflector_opt.report.figures`; this module only
re-exports them.

Each function returns a :class:`matplotlib.figure.Figure` on an Agg canvas: no pyplot, no
global state, safe in scripts, notebooks and worker processes. Single-panel figures take an
optional ``ax`` (a :class:`matplotlib.axes.Axes`) to draw into; the figure returned is then
that axes' figure. Angles are in degrees, lengths in mm, voltages in V, on every axis label.
"""

from reflector_opt.report.figures._asbuilt import as_built_deviation_figure
from reflector_opt.report.figures._base import save_figure
from reflector_opt.report.figures._calibration import (
    angle_traces_figure,
    calibration_error_figure,
    calibration_plan_figure,
    segment_figure,
    tip_path_figure,
)
from reflector_opt.report.figures._optimiser import pareto_figure, sweep_figure
from reflector_opt.report.figures._planes import sensor_plane
from reflector_opt.report.figures._resolution import (
    resolution_difference_figure,
    resolution_maps_figure,
    surface_resolution_figure,
)
from reflector_opt.report.figures._response import sensor_curve_figure, sensor_maps_figure
from reflector_opt.report.figures._sections import cross_section_figure, sensor_section_figure
from reflector_opt.report.figures._tolerance import error_histograms, sensitivity_bars, yield_bars

__all__ = [
    "angle_traces_figure",
    "as_built_deviation_figure",
    "calibration_error_figure",
    "calibration_plan_figure",
    "cross_section_figure",
    "error_histograms",
    "pareto_figure",
    "resolution_difference_figure",
    "resolution_maps_figure",
    "save_figure",
    "segment_figure",
    "sensitivity_bars",
    "sensor_curve_figure",
    "sensor_maps_figure",
    "sensor_plane",
    "sensor_section_figure",
    "surface_resolution_figure",
    "sweep_figure",
    "tip_path_figure",
    "yield_bars",
]
