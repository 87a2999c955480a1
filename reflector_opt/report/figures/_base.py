"""What every figure shares: a figure on its own Agg canvas, a map over pitch × roll, the worst
pose marked on it, and atomic saving.

No pyplot and no global state, so the figures are safe in scripts, notebooks and worker
processes. Angles are in degrees on every axis label.
"""

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from reflector_opt.util._fileio import atomic_path

#: Axis label of the pitch γ, degrees.
PITCH_LABEL = "pitch γ (°)"
#: Axis label of the roll α, degrees.
ROLL_LABEL = "roll α (°)"

#: Room left around a map, as a share of its span, so that the worst-pose cross at its
#: edge is drawn whole inside the axes.
WORST_MARKER_PAD = 0.05


def new_figure(figsize=(6.0, 4.0)):
    """An empty figure with constrained layout on its own Agg canvas.

    Parameters
    ----------
    figsize : tuple of float, optional
        (width, height), inches.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def single_axes(ax, figsize=(6.0, 4.0)):
    """The axes to draw a single-panel figure into: ``ax`` itself, or a new figure's one.

    Parameters
    ----------
    ax : matplotlib.axes.Axes or None
        Axes given by the caller.
    figsize : tuple of float, optional
        (width, height) of a new figure, inches.

    Returns
    -------
    fig : matplotlib.figure.Figure
    ax : matplotlib.axes.Axes
    """
    if ax is not None:
        return ax.figure, ax
    fig = new_figure(figsize)
    return fig, fig.add_subplot()


def pose_map(fig, ax, pitch_deg, roll_deg, values, label, cmap="viridis"):
    """Colour map of ``values`` over the pose grid, pitch across and roll up, with its colour bar.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    ax : matplotlib.axes.Axes
    pitch_deg, roll_deg : array_like
        The grid's axes, degrees: shapes (n_pitch,) and (n_roll,).
    values : array_like
        Shape (n_pitch, n_roll).
    label : str
        Label of the colour bar, with its unit.
    cmap : str, optional
        Matplotlib colour map.

    Returns
    -------
    matplotlib.collections.QuadMesh
    """
    mesh = ax.pcolormesh(pitch_deg, roll_deg, np.asarray(values).T, shading="auto", cmap=cmap)
    fig.colorbar(mesh, ax=ax, label=label)
    ax.set_xlabel(PITCH_LABEL)
    ax.set_ylabel(ROLL_LABEL)
    ax.set_aspect("equal")
    return mesh


def side_view(ax, horizontal, title, **title_options):
    """Dress the axes of a side view: ``horizontal`` (mm) across, z (mm) up, one scale, a grid.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    horizontal : str
        What the horizontal axis measures, e.g. ``"x"``; its label adds the unit, mm.
    title : str
    **title_options
        Passed to :meth:`matplotlib.axes.Axes.set_title` (e.g. ``fontsize``).
    """
    ax.set_xlabel(f"{horizontal} (mm)")
    ax.set_ylabel("z (mm)")
    ax.set_title(title, **title_options)
    ax.set_aspect("equal")
    ax.grid(True, alpha=0.3)


def mark_worst(ax, pitch_deg, roll_deg, values):
    """A red cross on the worst (largest) pose of a map, the axes widened so that it lies
    inside them whole (:data:`WORST_MARKER_PAD`).

    The cross is for the panel's title to name, not for a legend over the map.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    pitch_deg, roll_deg : array_like
        The grid's axes, degrees: shapes (n_pitch,) and (n_roll,).
    values : array_like
        Shape (n_pitch, n_roll).
    """
    i, j = np.unravel_index(np.argmax(values), np.shape(values))
    ax.plot(pitch_deg[i], roll_deg[j], "x", color="red", markersize=10, mew=2, label="worst")
    for limits, grid in ((ax.set_xlim, pitch_deg), (ax.set_ylim, roll_deg)):
        cell = abs(grid[1] - grid[0]) if len(grid) > 1 else 1.0
        pad = WORST_MARKER_PAD * (grid[-1] - grid[0]) + 0.5 * cell
        limits(grid[0] - pad, grid[-1] + pad)


def save_figure(fig, path, dpi=150):
    """Write a figure atomically; the format follows the file suffix (``.png``, ``.svg``, …).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    path : str or pathlib.Path
    dpi : int, optional
    """
    suffix = Path(path).suffix
    with atomic_path(path, suffix=suffix) as tmp:
        fig.savefig(tmp, dpi=dpi, format=suffix.lstrip(".") or "png")
