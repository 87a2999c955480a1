"""The optimiser's results: the Pareto front of resolution against margin, and a sweep of one
design variable."""

import numpy as np

from reflector_opt.report.figures._base import new_figure, single_axes


def pareto_figure(front, ax=None):
    """Worst-case resolution against distance-window margin.

    Parameters
    ----------
    front : reflector_opt.optimiser._pareto.ParetoFront
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        Worst-case 1σ pitch and roll resolution (degrees) of the optimised design at each
        required margin (mm) and, where the front was traced in conditions, its in-use
        worst-case total error; levels no design meets are marked along the top. Once the
        yields are estimated (:func:`reflector_opt.optimiser._robust.front_yield`), a second
        axis shows each point's yield with its 95 % interval.
    """
    fig, ax = single_axes(ax)
    points = front.feasible_points
    margin = np.array([p.required_margin_mm for p in points])
    ax.plot(margin, [p.worst_pitch_deg for p in points], "o-", label="pitch")
    ax.plot(margin, [p.worst_roll_deg for p in points], "s--", label="roll")
    in_use = np.array([p.worst_case_deg for p in points])
    label = "worst-case 1σ resolution (°)"
    if np.isfinite(in_use).any():  # the floor and the in-use error, a decade apart
        ax.plot(margin, in_use, "^-", color="C3", label="in-use worst case")
        ax.set_yscale("log")
        label = "worst case (°): white-noise 1σ, in use"
    blocked = [p.required_margin_mm for p in front.points if not p.feasible]
    if blocked:
        top = ax.get_ylim()[1]
        ax.plot(blocked, [top] * len(blocked), "x", color="black", label="no design")
    ax.set_xlabel("required distance-window margin (mm)")
    ax.set_ylabel(label)
    ax.set_title("Resolution against robustness to manufacturing error")
    ax.grid(True, alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    if front.yield_basis is not None and points:
        fraction = np.array([p.yield_fraction for p in points])
        bounds = np.array([[p.yield_low, p.yield_high] for p in points])
        twin = ax.twinx()
        bar = twin.errorbar(
            margin,
            fraction,
            yerr=np.abs(bounds.T - fraction),
            fmt="d:",
            color="C2",
            capsize=3,
        )
        twin.set_ylim(0, 1.05)
        judged = "all targets" if front.yield_basis["calibrated"] else "distance window"
        twin.set_ylabel(f"yield, {judged} (95 % interval)")
        handles.append(bar)
        labels.append(f"yield ({front.yield_basis['samples']} units)")
    ax.legend(handles, labels, loc="center left")
    return fig


def sweep_figure(rows, path):
    """The worst-case resolution, the nominal calibrated RMS error and the yield (if sampled)
    against one swept variable.

    The upper panel is what the optimiser minimises, the in-use worst-case error (where the
    rows have it), with the white-noise floor beside it (the worst-case 1σ resolution over
    the workspace, pitch and roll) on a log scale; the lower one the calibrated error and the
    yield; the legends sit below each panel, outside the data.

    Parameters
    ----------
    rows : list of dict
        :func:`reflector_opt.tolerance._sweep.sweep` rows.
    path : str
        The variable on the horizontal axis.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = new_figure(figsize=(6.0, 6.5))
    top, ax = fig.subplots(2, 1, sharex=True)
    ok = [r for r in rows if r["status"] == "ok"]
    x = [r[path] for r in ok]
    for angle, style in (("pitch", "o-"), ("roll", "s--")):
        values = [r[f"nominal_resolution_{angle}_deg"] for r in ok]
        top.plot(x, values, style, label=f"worst 1σ resolution, {angle}")
        ax.plot(x, [r[f"nominal_rms_{angle}_deg"] for r in ok], style, label=f"RMS {angle}")
    if ok and "nominal_worst_case_deg" in ok[0]:
        top.plot(x, [r["nominal_worst_case_deg"] for r in ok], "^-", color="C3", label="in use")
        top.set_yscale("log")
        top.set_ylabel("worst case (°): in use,\nwhite-noise 1σ resolution")
    else:
        top.set_ylabel("worst-case 1σ resolution (°)")
    ax.set_xlabel(path)
    ax.set_ylabel("nominal calibrated RMS error (°)")
    handles, labels = ax.get_legend_handles_labels()
    if ok and "yield" in ok[0]:
        twin = ax.twinx()
        twin.plot(x, [r["yield"] for r in ok], "d:", color="C2", label="yield")
        twin.set_ylim(0, 1.05)
        twin.set_ylabel("yield")
        more = twin.get_legend_handles_labels()
        handles, labels = handles + more[0], labels + more[1]
    for panel, entries in ((top, top.get_legend_handles_labels()), (ax, (handles, labels))):
        panel.grid(True, alpha=0.3)
        panel.legend(*entries, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=3)
    top.tick_params(labelbottom=True)
    return fig
