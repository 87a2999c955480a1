"""Figures. Each function returns a :class:`matplotlib.figure.Figure` on an Agg canvas: no
pyplot, no global state, safe in scripts, notebooks and worker processes.
"""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from reflector_opt.fileio import atomic_path

__all__ = [
    "error_histograms",
    "pareto_figure",
    "save_figure",
    "sensitivity_bars",
    "sweep_figure",
    "yield_bars",
]


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


# --- tolerance studies ---------------------------------------------------------------------


def _figure(size=(6.0, 4.0)):
    """An empty figure on an Agg canvas."""
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def error_histograms(study):
    """Histograms of the calibrated RMS and maximum errors over the samples, degrees.

    Parameters
    ----------
    study : reflector_opt.tolerance.ToleranceStudy

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = _figure((8.0, 3.6))
    ok = [r for r in study.records if r["status"] == "ok"]
    targets = study.targets
    for ax, kind, target in zip(
        fig.subplots(1, 2), ("rms", "max"), (targets.rms_deg, targets.max_deg), strict=True
    ):
        for angle in ("pitch", "roll"):
            ax.hist([r[f"{kind}_{angle}_deg"] for r in ok], bins=30, alpha=0.6, label=angle)
        ax.axvline(target, color="black", linestyle="--", label="target")
        ax.set_xlabel(f"calibrated {'RMS' if kind == 'rms' else 'maximum'} error (°)")
        ax.set_ylabel("units")
        ax.legend()
    fig.suptitle(f"{len(study.records)} simulated units")
    return fig


def yield_bars(study):
    """Fraction of units meeting each target and all of them."""
    fig = _figure((5.0, 3.6))
    ax = fig.add_subplot()
    y = study.summary["yield"]
    labels = ["window", "rms", "max", "all"]
    ax.bar(labels, [y[k] for k in labels], color=["C0", "C0", "C0", "C1"])
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("yield")
    t = study.targets
    ax.set_title(f"targets: RMS ≤ {t.rms_deg:g}°, max ≤ {t.max_deg:g}°")
    return fig


def sensitivity_bars(study):
    """One-at-a-time mean increase of the RMS error and Sobol total indices per tolerance."""
    panels = [p for p in (study.one_at_a_time, study.sobol) if p]
    fig = _figure((6.5, 2.2 + 2.2 * len(panels)))
    axes = fig.subplots(len(panels), 1, squeeze=False)[:, 0] if panels else []
    row = 0
    if study.one_at_a_time:
        rows = [r for r in study.one_at_a_time if r["tolerance"] != "none"]
        ax = axes[row]
        ax.barh(
            [r["tolerance"] for r in rows],
            [r["mean_increase_deg"] or 0.0 for r in rows],
        )
        ax.set_xlabel("mean increase of the worse RMS error, alone (°)")
        row += 1
    if study.sobol:
        groups = study.sobol["groups"]
        ax = axes[row]
        total = np.array([g["total"] if g["total"] is not None else np.nan for g in groups])
        ci = np.array([[v if v is not None else np.nan for v in g["total_ci"]] for g in groups])
        err = np.abs(ci.T - total)
        ax.barh([g["tolerance"] for g in groups], total, xerr=err)
        ax.set_xlabel("Sobol total index of the worse RMS error (95 % interval)")
    return fig


def sweep_figure(rows, path):
    """Nominal calibrated RMS error (and yield, if sampled) against one swept variable.

    Parameters
    ----------
    rows : list of dict
        :func:`reflector_opt.tolerance.sweep.sweep` rows.
    path : str
        The variable on the horizontal axis.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = _figure()
    ax = fig.add_subplot()
    ok = [r for r in rows if r["status"] == "ok"]
    x = [r[path] for r in ok]
    for angle, style in (("pitch", "o-"), ("roll", "s--")):
        ax.plot(x, [r[f"nominal_rms_{angle}_deg"] for r in ok], style, label=f"RMS {angle}")
    ax.set_xlabel(path)
    ax.set_ylabel("nominal calibrated RMS error (°)")
    ax.grid(True, alpha=0.3)
    if ok and "yield" in ok[0]:
        twin = ax.twinx()
        twin.plot(x, [r["yield"] for r in ok], "d:", color="C2", label="yield")
        twin.set_ylim(0, 1.05)
        twin.set_ylabel("yield")
        twin.legend(loc="upper right")
    ax.legend(loc="upper left")
    return fig
