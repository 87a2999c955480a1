"""Figures. Each function returns a :class:`matplotlib.figure.Figure` on an Agg canvas: no
pyplot, no global state, safe in scripts, notebooks and worker processes.

Single-panel figures take an optional ``ax`` (a :class:`matplotlib.axes.Axes`) to draw into;
the figure returned is then that axes' figure. Angles are in degrees, lengths in mm, voltages
in V, on every axis label.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from reflector_opt.calibration.segment import AXES, tip_pose, validation_motion
from reflector_opt.design.parts import CadParameters, package_parameters
from reflector_opt.model.forward import respond
from reflector_opt.model.geometry import rotate_centre, trace_axis
from reflector_opt.model.optics import beam_radius
from reflector_opt.util.fileio import atomic_path

__all__ = [
    "angle_traces_figure",
    "as_built_deviation_figure",
    "calibration_error_figure",
    "cross_section_figure",
    "error_histograms",
    "pareto_figure",
    "resolution_maps_figure",
    "save_figure",
    "segment_figure",
    "sensitivity_bars",
    "sensor_curve_figure",
    "sensor_maps_figure",
    "sensor_section_figure",
    "sweep_figure",
    "tip_path_figure",
    "yield_bars",
]

PITCH_LABEL = "pitch γ (°)"
ROLL_LABEL = "roll α (°)"


def _new_figure(figsize=(6.0, 4.0)):
    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _single_axes(ax, figsize=(6.0, 4.0)):
    if ax is not None:
        return ax.figure, ax
    fig = _new_figure(figsize)
    return fig, fig.add_subplot()


def _map(fig, ax, pitch_deg, roll_deg, values, label, cmap="viridis"):
    """Colour map of ``values`` (shape (n_pitch, n_roll)) with pitch across, roll up."""
    mesh = ax.pcolormesh(pitch_deg, roll_deg, np.asarray(values).T, shading="auto", cmap=cmap)
    fig.colorbar(mesh, ax=ax, label=label)
    ax.set_xlabel(PITCH_LABEL)
    ax.set_ylabel(ROLL_LABEL)
    ax.set_aspect("equal")
    return mesh


#: Room left around a map, as a share of its span, so that the worst-pose cross at its
#: edge is drawn whole inside the axes.
WORST_MARKER_PAD = 0.05


def _mark_worst(ax, pitch_deg, roll_deg, values):
    """A red cross on the worst pose, the axes widened so that it lies inside them whole; the
    cross is named in the panel's title, not in a legend over the map."""
    i, j = np.unravel_index(np.argmax(values), np.shape(values))
    ax.plot(pitch_deg[i], roll_deg[j], "x", color="red", markersize=10, mew=2, label="worst")
    for limits, grid in ((ax.set_xlim, pitch_deg), (ax.set_ylim, roll_deg)):
        cell = abs(grid[1] - grid[0]) if len(grid) > 1 else 1.0
        pad = WORST_MARKER_PAD * (grid[-1] - grid[0]) + 0.5 * cell
        limits(grid[0] - pad, grid[-1] + pad)


def sensor_curve_figure(design, sensor=0, metrics=None, ax=None):
    """Output voltage against distance to a flat target, the design's window shaded.

    The paper's Fig. 2d view: the modelled flat-target curve
    (:meth:`~reflector_opt.model.sensors.SensorModel.flat_coupling` through
    :meth:`~reflector_opt.model.sensors.SensorModel.output_voltage`), the sensor's usable range as
    dashed lines and the distances the design uses over its workspace shaded.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    sensor : int, optional
        Index of the sensor.
    metrics : reflector_opt.analysis.metrics.DesignMetrics, optional
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
    fig, ax = _single_axes(ax)
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
    design : reflector_opt.design.design.Design
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
    fig = _new_figure((4.2 * n, 7.0))
    axes = fig.subplots(2, n, squeeze=False)
    for i, placement in enumerate(design.sensors):
        _map(fig, axes[0, i], pitch, roll, response.distance_mm[..., i], "distance d (mm)")
        axes[0, i].set_title(f"{placement.name}: distance")
        _map(fig, axes[1, i], pitch, roll, response.volts[..., i], "output voltage (V)", "magma")
        axes[1, i].set_title(f"{placement.name}: voltage")
    return fig


def resolution_maps_figure(metrics, design):
    """Cramér–Rao 1σ pitch and roll resolution and the condition number of J over the grid.

    Parameters
    ----------
    metrics : reflector_opt.analysis.metrics.DesignMetrics
    design : reflector_opt.design.design.Design
        The design the metrics belong to (its workspace gives the grid).

    Returns
    -------
    matplotlib.figure.Figure
        Three maps, the worst pose of each marked with a red cross.
    """
    pitch, roll = design.workspace.axes(metrics.step_deg)
    fig = _new_figure((13.0, 4.0))
    panels = (
        (metrics.resolution_pitch_deg, "1σ pitch resolution (°)", "pitch resolution", "°"),
        (metrics.resolution_roll_deg, "1σ roll resolution (°)", "roll resolution", "°"),
        (metrics.condition, "condition number of J (–)", "condition number", ""),
    )
    for ax, (values, label, title, unit) in zip(fig.subplots(1, 3), panels, strict=True):
        _map(fig, ax, pitch, roll, values, label)
        _mark_worst(ax, pitch, roll, values)
        ax.set_title(f"{title}: worst {np.max(values):.3g}{unit} (red ×)")
    return fig


def resolution_difference_figure(metrics_a, metrics_b, design):
    """Where design B resolves better or worse than A: B − A of the 1σ resolution maps.

    Parameters
    ----------
    metrics_a, metrics_b : reflector_opt.analysis.metrics.DesignMetrics
        The two designs' metrics on the same grid.
    design : reflector_opt.design.design.Design
        Either design (its workspace gives the shared grid).

    Returns
    -------
    matplotlib.figure.Figure
        Two maps (pitch, roll), B − A in degrees, blue where B is better.
    """
    pitch, roll = design.workspace.axes(metrics_a.step_deg)
    fig = _new_figure((9.0, 4.0))
    for ax, angle in zip(fig.subplots(1, 2), ("pitch", "roll"), strict=True):
        values = np.asarray(getattr(metrics_b, f"resolution_{angle}_deg")) - np.asarray(
            getattr(metrics_a, f"resolution_{angle}_deg")
        )
        mesh = _map(fig, ax, pitch, roll, values, f"B − A, 1σ {angle} resolution (°)", "RdBu_r")
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
        :func:`reflector_opt.analysis.surface.resolution_against_surface`.
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = (_new_figure((6.0, 3.8)), None) if ax is None else (ax.figure, ax)
    ax = ax or fig.subplots()
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
        :func:`reflector_opt.report.asbuilt.deviation_records` gives them.
    words : dict, optional
        Parameter name → the label of its row (default: the name).

    Returns
    -------
    matplotlib.figure.Figure
    """
    words = words or {}
    names = list(dict.fromkeys(r["name"] for _, records in series for r in records))
    row = {name: k for k, name in enumerate(names)}
    fig = _new_figure((7.5, 1.4 + 0.3 * len(names)))
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


def pareto_figure(front, ax=None):
    """Worst-case resolution against distance-window margin.

    Parameters
    ----------
    front : reflector_opt.optimise.pareto.ParetoFront
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        Worst-case 1σ pitch and roll resolution (degrees) of the optimised design at each
        required margin (mm); levels no design meets are marked along the top. Once the
        yields are estimated (:func:`reflector_opt.optimise.robust.front_yield`), a second
        axis shows each point's yield with its 95 % interval.
    """
    fig, ax = _single_axes(ax)
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


def calibration_error_figure(result):
    """Estimation error of a simulated calibration over the validation poses.

    Parameters
    ----------
    result : reflector_opt.calibration.simulation.CalibrationResult

    Returns
    -------
    matplotlib.figure.Figure
        Two maps (pitch and roll error, degrees) with each validation pose coloured by the
        estimate minus the truth.
    """
    val = result.protocol.validation
    error = result.estimate(val.volts) - val.angles_deg
    limit = float(np.max(np.abs(error)))
    fig = _new_figure((10.0, 4.2))
    for ax, j, name in zip(fig.subplots(1, 2), (0, 1), AXES, strict=True):
        points = ax.scatter(
            val.angles_deg[:, 0],
            val.angles_deg[:, 1],
            c=error[:, j],
            s=3,
            cmap="coolwarm",
            vmin=-limit,
            vmax=limit,
            linewidths=0,
        )
        fig.colorbar(points, ax=ax, label=f"{name} error (°)")
        rms = result.total.rms_deg[j]
        ax.set_title(f"{result.model.name}: {name} error, RMS {rms:.3f}°")
        ax.set_xlabel(PITCH_LABEL)
        ax.set_ylabel(ROLL_LABEL)
        ax.set_aspect("equal")
    return fig


def angle_traces_figure(true_deg, estimated_deg, title="", names=AXES):
    """Estimated against actual angles over a motion (the paper's Fig. 5 view).

    Parameters
    ----------
    true_deg, estimated_deg : array_like
        Shape (n, k): the true and estimated angles at each sample, degrees.
    title : str, optional
    names : sequence of str, optional
        Name of each of the k angles.

    Returns
    -------
    matplotlib.figure.Figure
        One panel per angle, truth and estimate against sample, with the RMS error.
    """
    true_deg = np.asarray(true_deg, dtype=float)
    estimated_deg = np.asarray(estimated_deg, dtype=float)
    k = true_deg.shape[1]
    fig = _new_figure((8.0, 2.6 * k))
    axes = fig.subplots(k, 1, sharex=True, squeeze=False)[:, 0]
    for j, (ax, name) in enumerate(zip(axes, names, strict=True)):
        rms = float(np.sqrt(np.mean((estimated_deg[:, j] - true_deg[:, j]) ** 2)))
        ax.plot(true_deg[:, j], color="tab:orange", label=f"actual {name}")
        ax.plot(estimated_deg[:, j], color="tab:blue", linestyle="--", label=f"estimated {name}")
        ax.set_ylabel(f"{name} (°)")
        ax.set_title(f"{name}: RMS error {rms:.3f}°", fontsize=10)
        ax.legend(loc="upper right", fontsize=8)
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("sample (–)")
    if title:
        fig.suptitle(title)
    return fig


def segment_figure(errors):
    """Estimated against actual tip angle of a segment motion (the paper's Fig. 9 view).

    Parameters
    ----------
    errors : reflector_opt.calibration.segment.SegmentErrors
        From :func:`reflector_opt.calibration.segment.simulate_segment`.

    Returns
    -------
    matplotlib.figure.Figure
        The moved tip angle, actual and estimated, against sample, and the error below.
    """
    j = AXES.index(errors.axis)
    summary = errors.summary()
    fig = _new_figure((8.0, 5.0))
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(2, 1))
    top.plot(errors.true_angles_deg[:, j], color="tab:orange", label="actual")
    top.plot(errors.estimated_angles_deg[:, j], color="tab:blue", linestyle="--", label="estimated")
    top.set_ylabel(f"tip {errors.axis} (°)")
    top.set_title(
        f"segment {errors.axis} motion ±{errors.span_deg / 2:g}°: RMS error "
        f"{summary['rms_deg']:.3f}°, max {summary['max_deg']:.3f}°"
    )
    top.legend(loc="upper right", fontsize=8)
    bottom.plot(errors.axis_error_deg, color="tab:red")
    bottom.set_ylabel(f"{errors.axis} error (°)")
    bottom.set_xlabel("sample (–)")
    for ax in (top, bottom):
        ax.grid(True, alpha=0.3)
    return fig


def tip_path_figure(design, amplitude_deg=60.0, samples=200):
    """The segment and the path of its tip over the ±amplitude pitch and roll motions.

    The chain of ``design.mechanics.n_units`` units, ``link_length_mm`` apart, bends evenly
    (each unit takes amplitude / n_units) as in the paper's validation motions; drawn in the
    x–z plane for the pitch motion and the y–z plane for the roll motion.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    amplitude_deg : float, optional
        Tip amplitude, degrees.
    samples : int, optional
        Samples of one cycle.

    Returns
    -------
    matplotlib.figure.Figure
    """
    mech = design.mechanics
    fig = _new_figure((10.0, 4.8))
    for ax, axis, plane in zip(fig.subplots(1, 2), AXES, ((0, "x"), (1, "y")), strict=True):
        pitch, roll = validation_motion(axis, mech.n_units, amplitude_deg, 1, samples)
        column, name = plane
        _, tip = tip_pose(pitch, roll, mech.link_length_mm)
        ax.plot(tip[:, column], tip[:, 2], color="tab:blue", label="tip path")
        for k in (samples // 4, 3 * samples // 4, 0):  # the two extremes and the straight pose
            joints = [
                tip_pose(pitch[k, :n], roll[k, :n], mech.link_length_mm)[1]
                for n in range(1, mech.n_units + 1)
            ]
            chain = np.vstack([np.zeros(3), *joints])
            ax.plot(chain[:, column], chain[:, 2], "o-", color="grey", markersize=4)
        ax.plot([], [], "o-", color="grey", label="segment at 0° and the extremes")
        ax.set_xlabel(f"{name} (mm)")
        ax.set_ylabel("z (mm)")
        ax.set_title(f"{axis} motion ±{amplitude_deg:g}° ({mech.n_units} units)")
        ax.set_aspect("equal")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="lower center", fontsize=8)
    return fig


def cross_section_figure(design, poses_deg=((0.0, 0.0), (15.0, 0.0)), plane="xz", ax=None):
    """Section of the reflector sphere and the sensors at chosen poses (paper Fig. 3b/4a).

    The sphere posed by Eq 1 (s1 = Rx(α) Ry(γ) s0) is cut by the x–z (or y–z) plane through
    the rotation centre O; sensors in that plane are drawn with their optical axis up to
    where it meets the sphere at each pose; sensors off the plane are left out.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    poses_deg : sequence of (float, float), optional
        (pitch, roll) poses, degrees.
    plane : {"xz", "yz"}, optional
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    if plane not in ("xz", "yz"):
        raise ValueError(f"plane: expected 'xz' or 'yz', got {plane!r}")
    across, off = (0, 1) if plane == "xz" else (1, 0)
    fig, ax = _single_axes(ax, (6.0, 6.0))
    in_plane = np.abs(design.positions_mm[:, off]) < 1e-9
    colours = ("tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown")
    for k, pose in enumerate(poses_deg):
        _draw_posed_section(ax, design, pose, colours[k % len(colours)], (across, off), in_plane)
    for i in np.flatnonzero(in_plane):
        p, a = design.positions_mm[i], design.axes[i]
        ax.plot(p[across], p[2], "s", color="black", markersize=7)
        ax.annotate(
            design.sensors[i].name,
            (p[across], p[2]),
            textcoords="offset points",
            xytext=(6, 6),
            fontsize=9,
        )
        ax.arrow(p[across], p[2], 1.5 * a[across], 1.5 * a[2], head_width=0.3, color="black")
    ax.plot(0.0, 0.0, "o", color="black", markersize=5)
    ax.annotate("O", (0.0, 0.0), textcoords="offset points", xytext=(5, -12))
    ax.set_xlabel(f"{plane[0]} (mm)")
    ax.set_ylabel("z (mm)")
    ax.set_title(f"section in the {plane[0]}–z plane")
    ax.set_aspect("equal")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower left", fontsize=8)
    return fig


def _draw_posed_section(ax, design, pose, colour, coordinates, in_plane):
    """The sphere's section at one (pitch, roll) pose, its centre, and the optical axes of the
    ``in_plane`` sensors up to where they meet it; ``coordinates`` is (across, off) of the
    section plane."""
    (pitch, roll), (across, off) = pose, coordinates
    refl, positions = design.reflector, design.positions_mm
    centre = rotate_centre(refl.centre_mm, pitch, roll)
    half_chord_sq = refl.radius_mm**2 - centre[off] ** 2
    if half_chord_sq > 0:
        rho, angle = np.sqrt(half_chord_sq), np.linspace(0.0, 2.0 * np.pi, 361)
        ax.plot(
            centre[across] + rho * np.cos(angle),
            centre[2] + rho * np.sin(angle),
            color=colour,
            label=f"pitch {pitch:g}°, roll {roll:g}°",
        )
    ax.plot(centre[across], centre[2], "+", color=colour)
    if in_plane.any():
        hit = trace_axis(
            positions[in_plane], design.axes[in_plane], refl.centre_mm, refl.radius_mm, pitch, roll
        ).point_mm
        for p, h in zip(positions[in_plane], np.reshape(hit, (-1, 3)), strict=True):
            ax.plot([p[across], h[across]], [p[2], h[2]], ":", color=colour)
            ax.plot(h[across], h[2], ".", color=colour)


def sensor_plane(design, sensor):
    """The vertical plane that holds a sensor's optical axis, as an origin and two directions.

    The plane contains the sensor position f, the vertical z and the horizontal part of the
    optical axis a (the radial direction of f if a is vertical, +x if f is on the axis too).
    Its in-plane coordinates are (along, z): ``along`` measured from the point of the plane
    nearest the unit's axis, positive towards the sensor's side, so the sensor sits on the
    right looking left.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    sensor : int
        Index of the sensor.

    Returns
    -------
    normal : numpy.ndarray, shape (3,)
        Unit normal n of the plane (horizontal).
    offset : float
        ``n · f``: signed distance of the plane from the unit's axis, mm.
    along : numpy.ndarray, shape (3,)
        Unit horizontal direction in the plane, pointing from the axis towards the sensor.
    """
    f, a = design.positions_mm[sensor], design.axes[sensor]
    horizontal = np.array([a[0], a[1], 0.0])
    for fallback in ([f[0], f[1], 0.0], [1.0, 0.0, 0.0]):
        if np.linalg.norm(horizontal) < 1e-9:
            horizontal = np.array(fallback)
    along = horizontal / np.linalg.norm(horizontal)
    if along @ f < 0:
        along = -along
    normal = np.cross(along, [0.0, 0.0, 1.0])
    return normal, float(normal @ f), along


def _extreme_poses(design, sensor, metrics):
    """Poses of the smallest and largest Eq 3 distance of one sensor on the metrics' grid."""
    if metrics is None:
        pitch, roll = design.workspace.axes(0.5)
        distance = respond(design, pitch[:, None], roll[None, :]).distance_mm[..., sensor]
    else:
        pitch, roll = design.workspace.axes(metrics.step_deg)
        distance = metrics.distance_mm[..., sensor]
    poses = []
    for k in (np.argmin(distance), np.argmax(distance)):
        i, j = np.unravel_index(k, distance.shape)
        poses.append((float(pitch[i]), float(roll[j]), float(distance[i, j])))
    return poses


def _section_circle(ax, centre, radius, normal, offset, along, **style):
    """Draw the circle a sphere (centre, radius) cuts from the plane; False if it misses."""
    depth = float(normal @ centre) - offset
    if radius**2 <= depth**2:
        return False
    rho = np.sqrt(radius**2 - depth**2)
    t = np.linspace(0.0, 2.0 * np.pi, 361)
    ax.plot(float(along @ centre) + rho * np.cos(t), centre[2] + rho * np.sin(t), **style)
    return True


def sensor_section_figure(design, sensor=0, metrics=None, params=None):
    """Section through one sensor's own plane: the sensor, its beam and its distance window.

    The vertical plane holding the sensor's optical axis (:func:`sensor_plane`) cuts the
    reflector sphere (Eq 1: s1 = Rx(α) Ry(γ) s0) at the zero pose and at the poses of the
    sensor's smallest and largest Eq 3 distance d over the workspace grid; the optical axis
    runs to where it meets the sphere at each (:func:`~reflector_opt.model.geometry.trace_axis`),
    inside the beam's 1/e radius ω(t) = sqrt(ω0² + (t tan θ)²) (Eq 4). A ruler along the axis
    from the sensor's face shows the usable range of the sensor part and the distances the
    design uses. The left panel is the whole section, with the shell's inner surface and the
    unit's envelope; the right one zooms on the sensor.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    sensor : int, optional
        Index of the sensor.
    metrics : reflector_opt.analysis.metrics.DesignMetrics, optional
        Gives the distances over the workspace grid; otherwise they are computed at 0.5°.
    params : reflector_opt.design.parts.CadParameters, optional
        Size of the sensor package drawn (the paper's NJL5901R-2 by default; a part that
        states its own package is drawn with it).

    Returns
    -------
    matplotlib.figure.Figure
    """
    params = package_parameters(params or CadParameters(), design.models)
    placement, model = design.sensors[sensor], design.models[sensor]
    plane = sensor_plane(design, sensor)
    low, high = _extreme_poses(design, sensor, metrics)
    fig = _new_figure((12.0, 4.6))
    whole, zoom = fig.subplots(1, 2, width_ratios=(1.1, 1.0))
    reach = _draw_posed_spheres((whole, zoom), design, sensor, plane, (low, high))
    used = (float(np.min([p[2] for p in (low, high)])), float(np.max([p[2] for p in (low, high)])))
    ruler = _draw_sensor((whole, zoom), design, sensor, plane, params, reach, used)
    offset = plane[1]
    _draw_surroundings(whole, design, plane)
    f, a, along = design.positions_mm[sensor], design.axes[sensor], plane[2]
    shown = max(reach, model.range_mm[1])  # the beam and the whole ruler
    span = 1.15 * (shown + params.sensor_depth_mm) - 2.0 * ruler
    mid_x, mid_z = _in_plane(f + 0.5 * (shown - params.sensor_depth_mm) * a, along)
    zoom.set_xlim(mid_x - span / 2, mid_x + span / 2)
    zoom.set_ylim(mid_z - span / 2, mid_z + span / 2)
    azimuth = np.degrees(np.arctan2(along[1], along[0]))
    for ax, title in ((whole, "section"), (zoom, "at the sensor")):
        ax.set_aspect("equal")
        ax.grid(True, alpha=0.3)
        ax.set_xlabel(f"along azimuth {round(azimuth)}° (mm)")
        ax.set_ylabel("z (mm)")
        ax.set_title(f"{placement.name}: {title}", fontsize=10)
    zoom.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, borderaxespad=0)
    side_note = f", {abs(offset):.2f} mm off the unit's axis" if abs(offset) > 1e-6 else ""
    fig.suptitle(
        f"{placement.name}: section in the vertical plane of its optical axis{side_note}",
        fontsize=11,
    )
    return fig


def _in_plane(points, along):
    """In-plane coordinates (along, z) of points in a sensor's plane, mm."""
    points = np.asarray(points, dtype=float)
    return points @ along, points[..., 2]


def _draw_posed_spheres(axes, design, sensor, plane, extremes):
    """The sphere's section and the axis hit at the zero pose and at the sensor's extreme
    poses, on every axes; returns the longest axial distance to the sphere, mm."""
    normal, offset, along = plane
    f, a, refl = design.positions_mm[sensor], design.axes[sensor], design.reflector
    low, high = extremes
    poses = (
        (0.0, 0.0, None, "tab:blue"),
        (low[0], low[1], f"smallest d = {low[2]:.2f} mm", "tab:green"),
        (high[0], high[1], f"largest d = {high[2]:.2f} mm", "tab:red"),
    )
    reach = []
    for pitch, roll, note, colour in poses:
        centre = rotate_centre(refl.centre_mm, pitch, roll)
        hit = trace_axis(f, a, refl.centre_mm, refl.radius_mm, pitch, roll)
        point = np.reshape(hit.point_mm, 3)
        reach.append(float(np.ravel(hit.axial_distance_mm)[0]))
        label = f"sphere at pitch {pitch:g}°, roll {roll:g}°" + (f": {note}" if note else "")
        for ax in axes:
            _section_circle(
                ax, centre, refl.radius_mm, normal, offset, along, color=colour, lw=1.2, label=label
            )
            ax.plot(*_in_plane(point, along), "o", color=colour, ms=4)
            ax.plot(*_in_plane(centre, along), "+", color=colour, ms=8)
    return max(reach)


def _draw_sensor(axes, design, sensor, plane, params, reach, used):
    """The sensor's package, its beam (Eq 4) up to ``reach`` and the rulers of its usable
    range and of the distances ``used``, on every axes; returns the rulers' offset, mm."""
    normal, _, along = plane
    placement, model = design.sensors[sensor], design.models[sensor]
    f, a = design.positions_mm[sensor], design.axes[sensor]
    side = np.cross(normal, a)  # in-plane, across the axis
    t = np.linspace(0.0, reach, 50)
    width = beam_radius(t, model.source_radius_mm, model.divergence_deg)
    beam = np.concatenate(
        [
            f + t[:, None] * a + width[:, None] * side,
            (f + t[:, None] * a - width[:, None] * side)[::-1],
        ]
    )
    ends = np.array([f, f + reach * a])
    depth = params.sensor_depth_mm
    corners = ((-1, 0), (1, 0), (1, -depth), (-1, -depth))
    package = np.array([f + s * params.sensor_length_mm / 2.0 * side + d * a for s, d in corners])
    ruler = -(float(np.max(width)) + 0.5)  # below the beam
    rulers = (
        (model.range_mm, "0.6", 7, f"usable range {model.range_mm[0]:g}–{model.range_mm[1]:g} mm"),
        (used, "tab:orange", 3.5, f"distances used {used[0]:.2f}–{used[1]:.2f} mm"),
    )
    for ax in axes:
        ax.fill(
            *_in_plane(beam, along), color="gold", alpha=0.35, lw=0, label="beam, 1/e radius (Eq 4)"
        )
        ax.plot(*_in_plane(ends, along), ":", color="black", lw=0.8)
        ax.fill(*_in_plane(package, along), color="black", label=f"{placement.name} ({model.name})")
        for (lo, hi), colour, lw, text in rulers:
            segment = f - ruler * side + np.outer((lo, hi), a)
            ax.plot(
                *_in_plane(segment, along), color=colour, lw=lw, solid_capstyle="butt", label=text
            )
    return ruler


def _draw_surroundings(ax, design, plane):
    """The shell's inner surface, the unit's envelope and the rotation centre O."""
    normal, offset, along = plane
    radius_in = design.reflector.inner_radius_mm
    _section_circle(
        ax,
        np.zeros(3),
        radius_in,
        normal,
        offset,
        along,
        color="0.4",
        ls="--",
        lw=0.8,
        label=f"shell inner surface (r = {radius_in:g} mm)",
    )
    envelope = design.mechanics.unit_diameter_mm / 2.0
    if envelope > abs(offset):
        edge = np.sqrt(envelope**2 - offset**2)
        for x in (-edge, edge):
            ax.axvline(x, color="0.6", lw=0.8, ls="-.")
        ax.plot([], [], color="0.6", lw=0.8, ls="-.", label="unit envelope")
    ax.plot(0.0, 0.0, "k.", ms=5)
    ax.annotate("O", (0.0, 0.0), textcoords="offset points", xytext=(4, -11))


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


# --- tolerance studies ---------------------------------------------------------------------


def error_histograms(study):
    """Histograms of the calibrated RMS and maximum errors over the samples, degrees.

    Parameters
    ----------
    study : reflector_opt.tolerance.ToleranceStudy

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = _new_figure((8.0, 3.6))
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
    fig = _new_figure((5.0, 3.6))
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
    fig = _new_figure((6.5, 2.2 + 2.2 * len(panels)))
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
        _sobol_panel(axes[row], study.sobol)
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


def sweep_figure(rows, path):
    """The worst-case resolution, the nominal calibrated RMS error and the yield (if sampled)
    against one swept variable.

    The upper panel is what the optimiser minimises (the worst-case 1σ resolution over the
    workspace, pitch and roll), the lower one the calibrated error and the yield; the
    legends sit below each panel, outside the data.

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
    fig = _new_figure(figsize=(6.0, 6.5))
    top, ax = fig.subplots(2, 1, sharex=True)
    ok = [r for r in rows if r["status"] == "ok"]
    x = [r[path] for r in ok]
    for angle, style in (("pitch", "o-"), ("roll", "s--")):
        values = [r[f"nominal_resolution_{angle}_deg"] for r in ok]
        top.plot(x, values, style, label=f"worst 1σ resolution, {angle}")
        ax.plot(x, [r[f"nominal_rms_{angle}_deg"] for r in ok], style, label=f"RMS {angle}")
    top.set_ylabel("worst-case 1σ resolution (°)\n(the optimiser's objective)")
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


# --- calibration planning ----------------------------------------------------------------------


def calibration_plan_figure(study):
    """Predicted RMS error against the number of calibration poses, per pattern and form.

    Parameters
    ----------
    study : reflector_opt.tolerance.planning.PlanStudy

    Returns
    -------
    matplotlib.figure.Figure
        One panel per angle, log-log, the units' Cramér–Rao floor as a line.
    """
    fig = _new_figure(figsize=(10.0, 4.0))
    axes = fig.subplots(1, 2, sharey=True)
    styles = {"raster": "*", "grid": "o", "sobol": "s", "spiral": "^"}
    forms = sorted({p.form for p in study.predictions})
    for k, (ax, angle) in enumerate(zip(axes, AXES, strict=True)):
        for c, form in enumerate(forms):
            for pattern, marker in styles.items():
                points = sorted(
                    (p.n_poses, p.rms_deg[k])
                    for p in study.predictions
                    if p.form == form and p.pattern == pattern
                )
                if points:
                    n, rms = zip(*points, strict=True)
                    ax.plot(n, rms, f"{marker}-", color=f"C{c}", label=f"{form}, {pattern}")
        floor = study.floor_rms_deg[k]
        ax.axhline(floor, color="k", lw=1)
        ax.axhline(1.1 * floor, color="k", lw=1, ls=":")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("calibration poses")
        ax.set_title(f"{angle} (floor — , +10 % ···)")
        ax.grid(True, alpha=0.3, which="both")
    axes[0].set_ylabel("predicted RMS error over built units (°)")
    axes[1].legend(fontsize=6, ncol=2)
    return fig
