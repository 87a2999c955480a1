"""Figures. Each function returns a :class:`matplotlib.figure.Figure` on an Agg canvas: no
pyplot, no global state, safe in scripts, notebooks and worker processes.
"""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from reflector_opt.fileio import atomic_path

__all__ = ["pareto_figure", "save_figure"]


def pareto_figure(front):
    """Worst-case resolution against distance-window margin.

    Parameters
    ----------
    front : reflector_opt.optimise.pareto.ParetoFront

    Returns
    -------
    matplotlib.figure.Figure
        Worst-case 1σ pitch and roll resolution (degrees) of the optimised design at each
        required margin (mm); levels no design meets are marked along the top.
    """
    fig = Figure(figsize=(6.0, 4.0), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    points = front.feasible_points
    margin = np.array([p.required_margin_mm for p in points])
    ax.plot(margin, [p.worst_pitch_deg for p in points], "o-", label="pitch")
    ax.plot(margin, [p.worst_roll_deg for p in points], "s--", label="roll")
    blocked = [p.required_margin_mm for p in front.points if not p.feasible]
    if blocked:
        top = ax.get_ylim()[1]
        ax.plot(blocked, [top] * len(blocked), "x", color="black", label="no design")
    ax.set_xlabel("required distance-window margin (mm)")
    ax.set_ylabel("worst-case 1σ resolution (°)")
    ax.set_title("Resolution against robustness to manufacturing error")
    ax.grid(True, alpha=0.3)
    ax.legend()
    return fig


def save_figure(fig, path, dpi=150):
    """Write a figure atomically; the format follows the file suffix (``.png``, ``.svg``, …).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    path : str or pathlib.Path
    dpi : int, optional
    """
    from pathlib import Path

    suffix = Path(path).suffix
    with atomic_path(path, suffix=suffix) as tmp:
        fig.savefig(tmp, dpi=dpi, format=suffix.lstrip(".") or "png")
