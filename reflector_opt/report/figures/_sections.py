"""Sections of the unit: the reflector sphere and the sensors cut by a vertical plane, the
x–z or y–z plane through O (the paper's Fig. 3b/4a) or the plane of one sensor's optical axis
with its beam and distance window."""

import numpy as np

from reflector_opt.design._parts import CadParameters, package_parameters
from reflector_opt.model._forward import respond
from reflector_opt.model._geometry import rotate_centre, trace_axis
from reflector_opt.model._optics import beam_radius
from reflector_opt.report.figures._base import new_figure, side_view, single_axes
from reflector_opt.report.figures._planes import in_plane, section_circle, sensor_plane


def cross_section_figure(design, poses_deg=((0.0, 0.0), (15.0, 0.0)), plane="xz", ax=None):
    """Section of the reflector sphere and the sensors at chosen poses (paper Fig. 3b/4a).

    The sphere posed by Eq 1 (s1 = Rx(α) Ry(γ) s0) is cut by the x–z (or y–z) plane through
    the rotation centre O; sensors in that plane are drawn with their optical axis up to
    where it meets the sphere at each pose; sensors off the plane are left out.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
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
    fig, ax = single_axes(ax, (6.0, 6.0))
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
    side_view(ax, plane[0], f"section in the {plane[0]}–z plane")
    ax.legend(loc="lower left", fontsize=8)
    return fig


def _draw_posed_section(ax, design, pose, colour, coordinates, in_plane):
    """The sphere's section at one (pitch, roll) pose, its centre, and the optical axes of the
    ``in_plane`` sensors up to where they meet it; ``coordinates`` is (across, off) of the
    section plane."""
    (pitch, roll), (across, off) = pose, coordinates
    refl, positions = design.reflector, design.positions_mm
    centre = rotate_centre(refl.centre_mm, pitch, roll)
    normal, along = np.eye(3)[off], np.eye(3)[across]  # the section plane through O
    label = f"pitch {pitch:g}°, roll {roll:g}°"
    section_circle(ax, centre, refl.radius_mm, normal, 0.0, along, color=colour, label=label)
    ax.plot(centre[across], centre[2], "+", color=colour)
    if in_plane.any():
        hit = trace_axis(
            positions[in_plane], design.axes[in_plane], refl.centre_mm, refl.radius_mm, pitch, roll
        ).point_mm
        for p, h in zip(positions[in_plane], np.reshape(hit, (-1, 3)), strict=True):
            ax.plot([p[across], h[across]], [p[2], h[2]], ":", color=colour)
            ax.plot(h[across], h[2], ".", color=colour)


def sensor_section_figure(design, sensor=0, metrics=None, params=None):
    """Section through one sensor's own plane: the sensor, its beam and its distance window.

    The vertical plane holding the sensor's optical axis
    (:func:`~reflector_opt.report.figures._planes.sensor_plane`) cuts the reflector sphere
    (Eq 1: s1 = Rx(α) Ry(γ) s0) at the zero pose and at the poses of the sensor's smallest
    and largest Eq 3 distance d over the workspace grid; the optical axis runs to where it
    meets the sphere at each (:func:`~reflector_opt.model._geometry.trace_axis`), inside the
    beam's 1/e radius ω(t) = sqrt(ω0² + (t tan θ)²) (Eq 4). A ruler along the axis from the
    sensor's face shows the usable range of the sensor part and the distances the design
    uses. The left panel is the whole section, with the shell's inner surface and the unit's
    envelope; the right one zooms on the sensor.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    sensor : int, optional
        Index of the sensor.
    metrics : reflector_opt.analysis._metrics.DesignMetrics, optional
        Gives the distances over the workspace grid; otherwise they are computed at 0.5°.
    params : reflector_opt.design._parts.CadParameters, optional
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
    fig = new_figure((12.0, 4.6))
    whole, zoom = fig.subplots(1, 2, width_ratios=(1.1, 1.0))
    reach = _draw_posed_spheres((whole, zoom), design, sensor, plane, (low, high))
    used = (float(np.min([p[2] for p in (low, high)])), float(np.max([p[2] for p in (low, high)])))
    ruler = _draw_sensor((whole, zoom), design, sensor, plane, params, reach, used)
    offset = plane[1]
    _draw_surroundings(whole, design, plane)
    f, a, along = design.positions_mm[sensor], design.axes[sensor], plane[2]
    shown = max(reach, model.range_mm[1])  # the beam and the whole ruler
    span = 1.15 * (shown + params.sensor_depth_mm) - 2.0 * ruler
    mid_x, mid_z = in_plane(f + 0.5 * (shown - params.sensor_depth_mm) * a, along)
    zoom.set_xlim(mid_x - span / 2, mid_x + span / 2)
    zoom.set_ylim(mid_z - span / 2, mid_z + span / 2)
    azimuth = np.degrees(np.arctan2(along[1], along[0]))
    for ax, title in ((whole, "section"), (zoom, "at the sensor")):
        side_view(ax, f"along azimuth {round(azimuth)}°", f"{placement.name}: {title}", fontsize=10)
    zoom.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, borderaxespad=0)
    side_note = f", {abs(offset):.2f} mm off the unit's axis" if abs(offset) > 1e-6 else ""
    fig.suptitle(
        f"{placement.name}: section in the vertical plane of its optical axis{side_note}",
        fontsize=11,
    )
    return fig


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
            section_circle(
                ax, centre, refl.radius_mm, normal, offset, along, color=colour, lw=1.2, label=label
            )
            ax.plot(*in_plane(point, along), "o", color=colour, ms=4)
            ax.plot(*in_plane(centre, along), "+", color=colour, ms=8)
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
            *in_plane(beam, along), color="gold", alpha=0.35, lw=0, label="beam, 1/e radius (Eq 4)"
        )
        ax.plot(*in_plane(ends, along), ":", color="black", lw=0.8)
        ax.fill(*in_plane(package, along), color="black", label=f"{placement.name} ({model.name})")
        for (lo, hi), colour, lw, text in rulers:
            segment = f - ruler * side + np.outer((lo, hi), a)
            ax.plot(
                *in_plane(segment, along), color=colour, lw=lw, solid_capstyle="butt", label=text
            )
    return ruler


def _draw_surroundings(ax, design, plane):
    """The shell's inner surface, the unit's envelope and the rotation centre O."""
    normal, offset, along = plane
    radius_in = design.reflector.inner_radius_mm
    section_circle(
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
