"""The figure of the size–accuracy frontier (:mod:`reflector_opt.optimise.size`)."""

from __future__ import annotations

__all__ = ["frontier_figure"]


def frontier_figure(rows, target_deg=None, ax=None):
    """Best achievable objective against the unit's diameter, one line per sensor part.

    Parameters
    ----------
    rows : sequence of dict
        Frontier rows (``part``, ``unit_diameter_mm``, ``status``, ``objective_deg``).
    target_deg : float, optional
        Drawn as a horizontal line.
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        Feasible points joined per part (degrees against mm); each part's largest size no
        design fits marked with a cross on the axis.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(figsize=(6.4, 4.0), layout="constrained")
    else:
        fig = ax.figure
    for part in dict.fromkeys(r["part"] for r in rows):
        own = sorted((r for r in rows if r["part"] == part), key=lambda r: r["unit_diameter_mm"])
        ok = [r for r in own if r["status"] == "feasible"]
        (line,) = ax.plot(
            [r["unit_diameter_mm"] for r in ok], [r["objective_deg"] for r in ok], "o-", label=part
        )
        failed = [r["unit_diameter_mm"] for r in own if r["status"] != "feasible"]
        if failed and ok:
            ax.plot([max(failed)], [ok[0]["objective_deg"]], "x", color=line.get_color())
    if target_deg is not None:
        ax.axhline(target_deg, color="0.4", linestyle="--", label=f"target {target_deg:g}°")
    ax.set_xlabel("unit diameter (mm)")
    ax.set_ylabel("objective, worst case (°)")
    ax.set_title("Size–accuracy frontier (× : largest size no design fits)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return fig
