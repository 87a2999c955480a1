"""The as-built identification: each parameter's deviation from the design, in prior stds."""

import numpy as np

from reflector_opt.report.figures._base import new_figure


def as_built_deviation_figure(series, words=None):
    """Each as-built parameter's deviation from the design in units of its prior std.

    One row per parameter, one colour per series (the batch's shared surface, then each
    unit); a bar of ±1 posterior std about each estimate; a filled marker where the data
    determine the parameter, an open one where it stays near its prior. The shaded band is
    the prior's ±1 std.

    Parameters
    ----------
    series : sequence of (str, list of dict)
        Label and records with ``name``, ``z`` (deviation / prior std), ``z_std``
        (posterior std / prior std) and ``determined``, as
        :func:`reflector_opt.report._asbuilt.deviation_records` gives them.
    words : dict, optional
        Parameter name → the label of its row (default: the name).

    Returns
    -------
    matplotlib.figure.Figure
    """
    words = words or {}
    names = list(dict.fromkeys(r["name"] for _, records in series for r in records))
    row = {name: k for k, name in enumerate(names)}
    fig = new_figure((7.5, 1.4 + 0.3 * len(names)))
    ax = fig.add_subplot()
    ax.axvspan(-1.0, 1.0, color="0.92", label="prior ±1 std")
    ax.axvline(0.0, color="0.4", linewidth=0.8)
    shifts = np.linspace(-0.25, 0.25, len(series)) if len(series) > 1 else [0.0]
    for k, ((label, records), shift) in enumerate(zip(series, shifts, strict=True)):
        colour = f"C{k % 10}"
        for determined in (True, False):
            chosen = [r for r in records if r["determined"] == determined]
            if not chosen:
                continue
            ax.errorbar(
                [r["z"] for r in chosen],
                [row[r["name"]] + shift for r in chosen],
                xerr=[r["z_std"] for r in chosen],
                fmt="o",
                color=colour,
                markerfacecolor=colour if determined else "white",
                markersize=5,
                capsize=2,
                linewidth=1,
                label=label if determined or not any(r["determined"] for r in records) else None,
            )
    ax.plot([], [], "o", color="0.3", label="determined")
    ax.plot([], [], "o", color="0.3", markerfacecolor="white", label="not determined")
    ax.set_yticks(range(len(names)), [words.get(n, n) for n in names], fontsize=8)
    ax.set_ylim(len(names) - 0.5, -0.5)
    ax.set_xlabel("deviation from the design / prior std (–)")
    ax.grid(True, axis="x", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return fig
