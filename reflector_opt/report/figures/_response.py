"""What each sensor sees: its voltage against distance to a flat target, and its distance (Eq 3)
and voltage over the workspace."""

import numpy as np

from reflector_opt.model._forward import respond
from reflector_opt.report.figures._base import new_figure, pose_map, single_axes


def sensor_curve_figure(design, sensor=0, metrics=None, ax=None):
    """Output voltage against distance to a flat target, the design's window shaded.

    The paper's Fig. 2d view: the modelled flat-target curve
    (:meth:`~reflector_opt.model._sensors.SensorModel.flat_coupling` through
    :meth:`~reflector_opt.model._sensors.SensorModel.output_voltage`), the sensor's usable range as
    dashed lines and the distances the design uses over its workspace shaded.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    sensor : int, optional
        Index of the sensor.
    metrics : reflector_opt.analysis._metrics.DesignMetrics, optional
        Gives the distance window; otherwise it is computed on the workspace grid at 0.5°.
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    model = design.models[sensor]
    if metrics is None:
        distance = respond(design, *design.workspace.grid(0.5)).distance_mm[..., sensor]
        lo, hi = float(np.min(distance)), float(np.max(distance))
    else:
        lo, hi = float(metrics.distance_min_mm[sensor]), float(metrics.distance_max_mm[sensor])
    top = max(2.0 * model.range_mm[1], 1.2 * hi)
    d = np.linspace(0.02, top, 400)
    volts = model.output_voltage(model.flat_coupling(d, design.reflector.reflectance))
    fig, ax = single_axes(ax)
    ax.plot(d, volts, color="tab:blue", label=f"{model.name}, flat target")
    ax.axvspan(lo, hi, color="tab:orange", alpha=0.3, label=f"used: {lo:.2f}–{hi:.2f} mm")
    for edge in model.range_mm:
        ax.axvline(edge, color="grey", linestyle="--", linewidth=1)
    ax.plot([], [], color="grey", linestyle="--", label="usable range")
    ax.set_xlabel("distance to reflector d (mm)")
    ax.set_ylabel("output voltage (V)")
    ax.set_title(f"{design.sensors[sensor].name}: voltage against distance")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def sensor_maps_figure(design, step_deg=0.5):
    """Distance (Eq 3) and output voltage of each sensor over pitch × roll.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    step_deg : float, optional
        Grid step, degrees.

    Returns
    -------
    matplotlib.figure.Figure
        Top row distance (mm), bottom row voltage (V), one column per sensor.
    """
    pitch, roll = design.workspace.axes(step_deg)
    response = respond(design, pitch[:, None], roll[None, :])
    n = len(design.sensors)
    fig = new_figure((4.2 * n, 7.0))
    axes = fig.subplots(2, n, squeeze=False)
    for i, placement in enumerate(design.sensors):
        pose_map(fig, axes[0, i], pitch, roll, response.distance_mm[..., i], "distance d (mm)")
        axes[0, i].set_title(f"{placement.name}: distance")
        pose_map(
            fig, axes[1, i], pitch, roll, response.volts[..., i], "output voltage (V)", "magma"
        )
        axes[1, i].set_title(f"{placement.name}: voltage")
    return fig
