"""A tolerance study: the calibrated errors' histograms, the yield per target, and the
sensitivity of the error to each tolerance (one at a time and Sobol indices)."""

import numpy as np

from reflector_opt.report.figures._base import new_figure


def error_histograms(study):
    """Histograms of the calibrated RMS and maximum errors over the samples, degrees.

    Parameters
    ----------
    study : reflector_opt.tolerance.ToleranceStudy

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = new_figure((8.0, 3.6))
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
    fig = new_figure((5.0, 3.6))
    ax = fig.add_subplot()
    y = study.summary["yield"]
    labels = [k for k in ("window", "rms", "max", "all") if y[k] is not None]
    ax.bar(labels, [y[k] for k in labels], color=["C0"] * (len(labels) - 1) + ["C1"])
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("yield")
    t = study.targets
    ax.set_title(f"targets: RMS ≤ {t.rms_deg:g}°, max ≤ {t.max_deg:g}°")
    return fig


def sensitivity_bars(study):
    """One-at-a-time mean increase of the RMS error, and the Sobol first-order and total
    indices per tolerance with their confidence intervals."""
    panels = [p for p in (study.one_at_a_time, study.sobol) if p]
    fig = new_figure((6.5, 2.2 + 2.2 * len(panels)))
    axes = iter(fig.subplots(len(panels), 1, squeeze=False)[:, 0] if panels else [])
    if study.one_at_a_time:
        rows = [r for r in study.one_at_a_time if r["tolerance"] != "none"]
        ax = next(axes)
        ax.barh(
            [r["tolerance"] for r in rows],
            [r["mean_increase_deg"] or 0.0 for r in rows],
        )
        ax.set_xlabel("mean increase of the worse RMS error, alone (°)")
    if study.sobol:
        _sobol_panel(next(axes), study.sobol)
    return fig


def _sobol_panel(ax, sobol):
    """First-order and total index per group as bars, each with its interval as an error bar.

    The error bar spans the interval itself (not a distance from the estimate), so an interval
    that does not contain its estimate is drawn as it is; indices outside [0, 1] are neither
    clipped nor hidden, and those outside beyond their interval are marked in red.
    """

    def values(key):
        return np.array([np.nan if g[key] is None else g[key] for g in sobol["groups"]])

    def bounds(key):
        return np.array(
            [[np.nan if v is None else v for v in g[f"{key}_ci"]] for g in sobol["groups"]]
        ).reshape(-1, 2)

    names = [g["tolerance"] for g in sobol["groups"]]
    y = np.arange(len(names), dtype=float)
    flagged = {(o["tolerance"], o["index"]) for o in sobol["outside"]}
    for key, label, shift, colour in (
        ("total", "total", -0.2, "C0"),
        ("first", "first-order", 0.2, "C1"),
    ):
        ci = bounds(key)
        ax.barh(y + shift, values(key), height=0.4, color=colour, label=label)
        red = np.array([(name, key) in flagged for name in names], dtype=bool)
        for rows, ecolour in ((~red, "black"), (red, "red")):
            if rows.any():
                ax.errorbar(
                    ci[rows].mean(axis=1),
                    (y + shift)[rows],
                    xerr=(ci[rows, 1] - ci[rows, 0]) / 2,
                    fmt="none",
                    ecolor=ecolour,
                    capsize=2,
                    linewidth=1,
                )
    for edge in (0.0, 1.0):
        ax.axvline(edge, color="grey", linewidth=0.6, linestyle=":")
    ax.set_yticks(y, names)
    ax.invert_yaxis()
    ax.legend(loc="upper right", fontsize="small")
    ax.set_xlabel(
        f"Sobol index of the worse RMS error ({100 * sobol['confidence']:g} % interval, "
        f"{sobol['rows']} rows)"
    )
