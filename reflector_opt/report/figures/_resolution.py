"""The Cramér–Rao 1σ resolution: its maps over the workspace, the difference of two designs',
and the worst case against the surface's specular fraction."""

import numpy as np

from reflector_opt.report.figures._base import mark_worst, new_figure, pose_map, single_axes


def resolution_maps_figure(metrics, design):
    """Cramér–Rao 1σ pitch and roll resolution and the condition number of J over the grid.

    Parameters
    ----------
    metrics : reflector_opt.analysis._metrics.DesignMetrics
    design : reflector_opt.design._design.Design
        The design the metrics belong to (its workspace gives the grid).

    Returns
    -------
    matplotlib.figure.Figure
        Three maps, the worst pose of each marked with a red cross.
    """
    pitch, roll = design.workspace.axes(metrics.step_deg)
    fig = new_figure((13.0, 4.0))
    panels = (
        (metrics.resolution_pitch_deg, "1σ pitch resolution (°)", "pitch resolution", "°"),
        (metrics.resolution_roll_deg, "1σ roll resolution (°)", "roll resolution", "°"),
        (metrics.condition, "condition number of J (–)", "condition number", ""),
    )
    for ax, (values, label, title, unit) in zip(fig.subplots(1, 3), panels, strict=True):
        pose_map(fig, ax, pitch, roll, values, label)
        mark_worst(ax, pitch, roll, values)
        ax.set_title(f"{title}: worst {np.max(values):.3g}{unit} (red ×)")
    return fig


def resolution_difference_figure(metrics_a, metrics_b, design):
    """Where design B resolves better or worse than A: B − A of the 1σ resolution maps.

    Parameters
    ----------
    metrics_a, metrics_b : reflector_opt.analysis._metrics.DesignMetrics
        The two designs' metrics on the same grid.
    design : reflector_opt.design._design.Design
        Either design (its workspace gives the shared grid).

    Returns
    -------
    matplotlib.figure.Figure
        Two maps (pitch, roll), B − A in degrees, blue where B is better.
    """
    pitch, roll = design.workspace.axes(metrics_a.step_deg)
    fig = new_figure((9.0, 4.0))
    for ax, angle in zip(fig.subplots(1, 2), ("pitch", "roll"), strict=True):
        values = np.asarray(getattr(metrics_b, f"resolution_{angle}_deg")) - np.asarray(
            getattr(metrics_a, f"resolution_{angle}_deg")
        )
        mesh = pose_map(fig, ax, pitch, roll, values, f"B − A, 1σ {angle} resolution (°)", "RdBu_r")
        limit = float(np.max(np.abs(values))) or 1.0
        mesh.set_clim(-limit, limit)
        ax.set_title(f"{angle}: B − A from {np.min(values):.3g}° to {np.max(values):.3g}°")
    return fig


def surface_resolution_figure(sweep, ax=None):
    """Worst-case 1σ resolution against the surface's specular fraction, beside the default.

    Parameters
    ----------
    sweep : dict
        ``{"design": rows, "default_design": rows}`` with the records of
        :func:`reflector_opt.analysis._surface.resolution_against_surface`.
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = single_axes(ax, (6.0, 3.8))
    styles = {"design": ("this design", "tab:blue"), "default_design": ("default design", "0.5")}
    for key, (label, colour) in styles.items():
        rows = sweep[key]
        f = [r["specular_fraction"] for r in rows]
        ax.plot(
            f, [r["worst_pitch_deg"] for r in rows], "-o", color=colour, label=f"{label}: pitch"
        )
        ax.plot(f, [r["worst_roll_deg"] for r in rows], "--s", color=colour, label=f"{label}: roll")
    ax.set_xlabel("specular fraction f (0 Lambertian, 1 mirror)")
    ax.set_ylabel("worst-case 1σ resolution (°)")
    ax.set_xlim(0.0, 1.0)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return fig
