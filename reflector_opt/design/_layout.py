"""Where everything goes: the dimensions of both printed parts, derived from a design.

Frame and poses are those of the design (docs/conventions.md): origin O at the spherical bearing's
centre, z along the backbone, the reflector part rotated by R = Rx(roll)·Ry(pitch) about O.
Angles about O: elevation e from the xy-plane (positive towards +z) and azimuth a from +x
towards +y, in degrees. The regions about O it plans are polar boxes
(:class:`~reflector_opt.design._polar.PolarBox`).

Physical layout (docs/cad.md has the cross-section):

* the **bearing** (the one ``mechanics.bearing`` names, the paper's GE 6 E by default) sits
  at O; its outer ring rests on a seat of the **body** (the upper end of the lower unit); the
  **reflector part** (the lower end of the upper unit) carries the shaft through the bore;
* the reflector part is a dome concentric with O (inner radius ``reflector.inner_radius_mm``)
  joined by a neck to a flange at the top (the next unit's body stands on it); below the dome
  hang one **reflecting patch** per sensor — the outer sphere of radius r_s about s0, kept only
  over the directions the sensor's beam reaches over the whole workspace plus its footprint;
* the body is a cylinder of the unit's diameter from which the space the rotating parts sweep
  over the workspace is removed (plus a running clearance); the sensors sit in windows of its
  wall, on the flexible strip lying in a vertical channel, and three tendon holes at 120° pass
  through body and flange.
"""

import itertools
import math
from dataclasses import dataclass

import numpy as np

from reflector_opt.design._parts import CadParameters, design_parameters, package_parameters
from reflector_opt.design._polar import (
    PolarBox,
    distance_to_sphere,
    drop_contained,
    polar_angles,
    polar_directions,
    relative_azimuth,
)
from reflector_opt.design._validation import check_centre_inside
from reflector_opt.model._geometry import check_collision, rotation_x, rotation_y, unit
from reflector_opt.model._optics import beam_radius
from reflector_opt.util._errors import InputError

#: Pose step used to find the reflecting band and the swept space, degrees.
SWEEP_STEP_DEG = 1.0
#: Angular resolution of the grids on which patch extremes are searched, degrees.
ANGLE_GRID_DEG = 0.1
#: Spacing of the points along a patch's outline whose sweep is traced, degrees.
OUTLINE_STEP_DEG = 0.5
#: Largest elevation range of one slice of a patch's swept space, degrees.
SLICE_DEG = 10.0
#: The swept-space cutters reach this far into the bearing pocket so that the two overlap
#: (their faceted spheres would otherwise leave slivers of body between them), mm. It must
#: exceed twice the coarsest chord tolerance (:data:`MAX_TOLERANCE_MM`).
POCKET_OVERLAP_MM = 0.1
#: A sensor window reaches at most this much farther into the body for its corners than for
#: its centre, mm (:func:`_window_wall`).
WINDOW_CORNER_REACH_MM = 1.0


@dataclass(frozen=True)
class Patch:
    """The reflecting patch one sensor needs, in the reflector part's own frame.

    Attributes
    ----------
    sensor : str
        Sensor name.
    elevation_deg : (float, float)
        Lowest elevation of the patch and the elevation of the band's top, degrees.
    azimuth_deg : (float, float)
        Azimuth range, degrees (may extend below −180 or above 180).
    seen_elevation_deg, seen_azimuth_deg : (float, float)
        Range of the points the sensor's axis and its Eq 3 nearest point reach, before the
        footprint margin, degrees.
    margin_mm : float
        Footprint margin added around the seen points, mm.
    outer_radius_mm : float
        Largest distance from O of the patch's reflecting surface, mm.
    lowest_z_mm : float
        Height of the lowest point of the patch's reflecting surface, mm.
    swept : tuple of PolarBox
        Space the patch occupies at some pose of the workspace, with clearance (the body
        keeps out of it), one box per elevation slice of the patch.
    """

    sensor: str
    elevation_deg: tuple[float, float]
    azimuth_deg: tuple[float, float]
    seen_elevation_deg: tuple[float, float]
    seen_azimuth_deg: tuple[float, float]
    margin_mm: float
    outer_radius_mm: float
    lowest_z_mm: float
    swept: tuple[PolarBox, ...]


@dataclass(frozen=True)
class SensorMount:
    """Where one sensor's window and channel are cut into the body.

    Attributes
    ----------
    name : str
    frame : numpy.ndarray, shape (3, 3)
        Rows: across the strip t, along the strip u, optical axis a.
    front_mm : numpy.ndarray, shape (3,)
        Sensor position f (front face centre), mm.
    pad_mm : numpy.ndarray, shape (3,)
        Centre of the pad: the channel floor the strip lies on, f − depth·a, mm.
    pad_distance_mm : float
        Distance of the pad plane from O, mm.
    window_length_mm : float
        Depth of the window from the pad plane into the cavity, mm.
    """

    name: str
    frame: np.ndarray
    front_mm: np.ndarray
    pad_mm: np.ndarray
    pad_distance_mm: float
    window_length_mm: float


@dataclass(frozen=True)
class Layout:
    """Every derived dimension of the two parts (lengths mm, angles degrees).

    Heights (``*_z_mm``) are z coordinates in the unit frame, O at 0.

    Attributes
    ----------
    lid_radius_mm : float
        Outer radius of the dome above the reflecting band, concentric with O.
    band_top_deg : float
        Elevation of the top of the reflecting band (where the dome starts).
    patches : tuple of Patch
        One reflecting patch per sensor.
    tilt_max_deg : float
        Largest tilt of the unit's z axis over the workspace.
    seat_z_mm : float
        The bearing seat: the outer ring's lower face.
    body_bottom_z_mm, body_top_z_mm, flange_z_mm, flange_top_z_mm : float
        Faces of the body and of the reflector part's flange.
    swing_radius_mm : float
        Radius about O that the inner ring and the shaft's end stay within.
    keepouts : tuple of PolarBox
        The space the rotating parts sweep over the workspace, with clearance, where it
        reaches into the body.
    tendon_azimuths_deg : tuple of float
        Azimuths of the three tendon holes.
    sensors : tuple of SensorMount
    reflector_walls_mm, body_walls_mm : dict of str to float
        The designed walls of each part by name, mm.
    min_wall_mm : float
        Printable minimum wall (``mechanics.min_wall_mm``).
    """

    params: CadParameters
    envelope_radius_mm: float
    sphere_radius_mm: float
    sphere_centre_mm: tuple[float, float, float]
    inner_radius_mm: float
    lid_radius_mm: float
    band_top_deg: float
    patches: tuple[Patch, ...]
    tilt_max_deg: float
    seat_z_mm: float
    body_bottom_z_mm: float
    body_top_z_mm: float
    flange_z_mm: float
    flange_top_z_mm: float
    shaft_radius_mm: float
    shaft_bottom_z_mm: float
    swing_radius_mm: float
    keepouts: tuple[PolarBox, ...]
    tendon_azimuths_deg: tuple[float, float, float]
    sensors: tuple[SensorMount, ...]
    reflector_walls_mm: dict
    body_walls_mm: dict
    min_wall_mm: float

    @property
    def bearing_pocket_radius_mm(self):
        """Radius of the free ball about O the body leaves for the bearing, mm."""
        return self.inner_radius_mm - self.params.clearance_mm


def workspace_rotations(design, step_deg=SWEEP_STEP_DEG):
    """Rotation matrices R = Rx(roll)·Ry(pitch) over the workspace grid, both ends included.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    step_deg : float
        Grid step, degrees.

    Returns
    -------
    numpy.ndarray
        Shape (n_poses, 3, 3).
    """
    pitch, roll = np.broadcast_arrays(*design.workspace.grid(step_deg))
    return (rotation_x(roll.ravel()) @ rotation_y(pitch.ravel())).reshape(-1, 3, 3)


def _grid(lo, hi, step=ANGLE_GRID_DEG):
    n = max(2, math.ceil((hi - lo) / step) + 1)
    return np.linspace(lo, hi, n)


def _seen_points(design, rotations):
    """Axis hits and Eq 3 nearest points of every sensor, in the reflector frame.

    Returns an array (n_poses, n_sensors, 2, 3) and the largest axial distance per sensor.
    """
    refl = design.reflector
    s0 = np.asarray(refl.centre_mm, dtype=float)
    f = design.positions_mm
    # f in the reflector frame at every pose: R^T f.
    f_local = np.einsum("pji,sj->psi", rotations, f)
    nearest = s0 + refl.radius_mm * unit(f_local - s0)
    a_local = unit(np.einsum("pji,sj->psi", rotations, design.axes))
    # The axis f + t·a meets the sphere ‖x − s0‖ = r_s first at t = −b − sqrt(b² − c),
    # b = a·(f − s0), c = ‖f − s0‖² − r_s² (the ray–sphere intersection of Eq 3's geometry).
    offset = f_local - s0
    check_collision(np.linalg.norm(offset, axis=-1) - refl.radius_mm)
    b = np.einsum("psi,psi->ps", a_local, offset)
    discriminant = b**2 - (np.einsum("psi,psi->ps", offset, offset) - refl.radius_mm**2)
    with np.errstate(invalid="ignore"):
        axial = -b - np.sqrt(discriminant)
    axial[(discriminant < 0) | (axial < 0)] = np.nan
    reached = np.isfinite(axial).all(0)
    if not reached.all():
        bad = [s.name for s, ok in zip(design.sensors, reached, strict=True) if not ok]
        raise InputError(f"sensors: the optical axis of {', '.join(bad)} misses the reflector")
    hit_points = f_local + axial[..., None] * a_local
    points = np.stack([hit_points, nearest], axis=2)
    return points, axial.max(axis=0)


def _moved_extremes(directions, rotations, mid_deg):
    """Least and greatest elevation and azimuth (from ``mid_deg``) of directions over the poses.

    ``directions`` has shape (m, k, 3): m edges of k directions each; returns four arrays of
    shape (m,), the extremes of each edge over its directions moved by every pose.
    """
    m, k = directions.shape[:2]
    # moved[p, :, j] = R_p · directions[j], as one matrix product over every pose
    moved = (rotations.reshape(-1, 3) @ directions.reshape(-1, 3).T).reshape(len(rotations), 3, -1)
    x, y, z = moved[:, 0], moved[:, 1], moved[:, 2]
    # as polar_angles, but arcsin (increasing) only at the extremes of the elevation's sine
    sine = np.clip(z / np.sqrt(x * x + y * y + z * z), -1.0, 1.0).reshape(-1, m, k)
    rel = relative_azimuth(np.degrees(np.arctan2(y, x)), mid_deg).reshape(-1, m, k)
    e_min, e_max = (np.degrees(np.arcsin(v)) for v in (sine.min((0, 2)), sine.max((0, 2))))
    return e_min, e_max, rel.min((0, 2)), rel.max((0, 2))


def _patch_sweeps(cuts, azimuth, rotations, margin_deg):
    """Angular box swept by each spherical rectangle (slice of ``cuts`` × azimuth) over the poses.

    A rotation about O moves directions only, so the sweep does not depend on the radius;
    the extremes of elevation and azimuth of a moved rectangle lie on its outline. Adjacent
    slices share their edge of constant elevation, which is moved once for both.
    """
    mid = 0.5 * (azimuth[0] + azimuth[1])
    a_edge = _grid(*azimuth, OUTLINE_STEP_DEG)
    # the edges of constant elevation: one per cut
    e_lo, e_hi, r_lo, r_hi = _moved_extremes(
        polar_directions(np.asarray(cuts)[:, None], a_edge[None, :]), rotations, mid
    )
    sweeps = []
    for i, (lo, hi) in enumerate(itertools.pairwise(cuts)):
        e_edge = _grid(lo, hi, OUTLINE_STEP_DEG)
        sides = polar_directions(e_edge[None, :], np.asarray(azimuth)[:, None]).reshape(1, -1, 3)
        s_lo, s_hi, sr_lo, sr_hi = _moved_extremes(sides, rotations, mid)
        low = min(float(e_lo[i]), float(e_lo[i + 1]), float(s_lo[0]))
        high = max(float(e_hi[i]), float(e_hi[i + 1]), float(s_hi[0]))
        left = min(float(r_lo[i]), float(r_lo[i + 1]), float(sr_lo[0]))
        right = max(float(r_hi[i]), float(r_hi[i + 1]), float(sr_hi[0]))
        elevation = (low - margin_deg, min(high + margin_deg, 90.0))
        sweeps.append((elevation, (mid + left - margin_deg, mid + right + margin_deg)))
    return sweeps


def _seen(design, params, rotations):
    """Angular range each sensor sees, before and after the footprint margin."""
    points, axial_max = _seen_points(design, rotations)
    elevation, azimuth = polar_angles(points)
    distance = np.linalg.norm(points, axis=-1)
    horizontal = np.hypot(points[..., 0], points[..., 1])
    seen = []
    for i, (sensor, model) in enumerate(zip(design.sensors, design.models, strict=True)):
        # one-way 1/e footprint radius of the beam at the farthest axial distance
        footprint = beam_radius(axial_max[i], model.source_radius_mm, model.divergence_deg)
        margin = params.footprint_factor * float(footprint) + params.band_margin_mm
        centre_az = math.degrees(math.atan2(sensor.position_mm[1], sensor.position_mm[0]))
        e_i = elevation[:, i].ravel()
        a_i = centre_az + relative_azimuth(azimuth[:, i].ravel(), centre_az)
        de = math.degrees(margin / distance[:, i].min())
        da = math.degrees(margin / horizontal[:, i].min())
        elevation_range = (float(e_i.min()), float(e_i.max()))
        azimuth_range = (float(a_i.min()), float(a_i.max()))
        seen.append((sensor.name, elevation_range, azimuth_range, margin, de, da))
    return seen


def _plan_patches(design, params, rotations, keep_deg):
    refl = design.reflector
    s0 = np.asarray(refl.centre_mm, dtype=float)
    seen = _seen(design, params, rotations)
    band_top = max(e[1] + de for _, e, _, _, de, _ in seen)
    if band_top >= 80.0:
        raise InputError("reflector: the sensors look too close to the top of the unit")
    r0 = refl.inner_radius_mm - params.clearance_mm - POCKET_OVERLAP_MM
    patches = []
    for name, (e_lo, e_hi), (a_lo, a_hi), margin, de, da in seen:
        elev = (e_lo - de, band_top)
        azim = (a_lo - da, a_hi + da)
        if elev[0] <= -80.0 or azim[1] - azim[0] >= 170.0:
            raise InputError(f"reflector: sensor {name} sees too wide a part of the sphere")
        cuts = np.linspace(*elev, math.ceil((elev[1] - elev[0]) / SLICE_DEG) + 1)
        swept, outer, lowest = [], 0.0, np.inf
        sweeps = _patch_sweeps(cuts, azim, rotations, keep_deg)
        for (lo, hi), (sw_e, sw_a) in zip(itertools.pairwise(cuts), sweeps, strict=True):
            dirs = polar_directions(_grid(lo, hi)[:, None], _grid(*azim)[None, :])
            reach = distance_to_sphere(dirs, s0, refl.radius_mm)
            r1 = float(reach.max())
            lowest = min(lowest, float((reach * dirs[..., 2]).min()))
            # Everything above the slice's lowest swept elevation is kept out up to its
            # radius: the body then has no thin lip over the sweep.
            swept.append(PolarBox(r0, r1 + params.clearance_mm, sw_e[0], 90.0, *sw_a))
            outer = max(outer, r1)
        patches.append(
            Patch(name, elev, azim, (e_lo, e_hi), (a_lo, a_hi), margin, outer, lowest, tuple(swept))
        )
    return band_top, tuple(patches)


def _shell_thickness(design, layout_patches, envelope_radius):
    """Thinnest reflecting shell over the patches, mm.

    The shell of a patch lies between its inner surface (radius r_i about O) and its
    reflecting surface: the sphere of radius r_s about s0 over the patch's elevations and
    azimuths (above the band's top the dome covers it, beside and below it nothing does).
    The wall is the least distance between the two, or from the inner surface to the envelope
    cylinder where that is nearer. For an inner point x the sphere's nearest point is
    y* = s0 + r_s·(x − s0)/‖x − s0‖, at r_s − ‖x − s0‖; the distance to the sphere grows with
    the angle from y* about s0, so where y* lies outside the patch the nearest point of the
    reflecting surface is on its outline, and for an outline point y the nearest inner point is
    r_i·y/‖y‖ (same direction, on the patch), at ‖y‖ − r_i. Hence the wall is the least of
    r_s − ‖x − s0‖ over the inner points whose y* lies over the patch and of ‖y‖ − r_i over
    the outline — the distance a mesh measures from the inner surface to the reflecting one
    (:func:`reflector_opt.cad._printability.shell_thickness_on_mesh`).
    """
    refl = design.reflector
    s0 = np.asarray(refl.centre_mm, dtype=float)
    thinnest = np.inf
    for p in layout_patches:
        elevation, azimuth = _grid(*p.elevation_deg), _grid(*p.azimuth_deg)
        x = refl.inner_radius_mm * polar_directions(elevation[:, None], azimuth[None, :])
        offset = x - s0
        distance = np.linalg.norm(offset, axis=-1)
        over = _over_patch(s0 + refl.radius_mm * offset / distance[..., None], p)
        to_sphere = np.where(over, refl.radius_mm - distance, np.inf)
        to_envelope = envelope_radius - np.hypot(x[..., 0], x[..., 1])
        sides = polar_directions(elevation[:, None], np.asarray(p.azimuth_deg)[None, :])
        ends = polar_directions(np.asarray(p.elevation_deg)[:, None], azimuth[None, :])
        outline = np.concatenate([sides.reshape(-1, 3), ends.reshape(-1, 3)])
        to_outline = distance_to_sphere(outline, s0, refl.radius_mm) - refl.inner_radius_mm
        thinnest = min(thinnest, float(to_sphere.min()), float(to_envelope.min()))
        thinnest = min(thinnest, float(to_outline.min()))
    return thinnest


def _over_patch(points, patch):
    """True where points (shape (..., 3), mm) lie within a patch's elevations and azimuths."""
    elevation, azimuth = polar_angles(points)
    lo, hi = patch.azimuth_deg
    half = 0.5 * (hi - lo)
    inside = np.abs(relative_azimuth(azimuth, 0.5 * (lo + hi))) <= half + 1e-9
    return (
        inside
        & (elevation >= patch.elevation_deg[0] - 1e-9)
        & (elevation <= patch.elevation_deg[1] + 1e-9)
    )


def _sensor_frame(axis):
    a = unit(axis)
    across = unit(np.cross([0.0, 0.0, 1.0], a))
    return np.stack([across, np.cross(a, across), a])


def window_wall_mm(design, params=None):
    """Wall of the body above each sensor's window, mm.

    The window holds the sensor package (``sensor_length_mm`` along the strip, which runs
    in the vertical plane of the optical axis a) with ``sensor_pocket_clearance_mm`` around
    it; its top lies at ``f_z + |u_z|·length/2`` with u the direction along the strip, so
    the wall up to the body's top face (``body_top_mm``) is
    ``body_top − f_z − |u_z|·length/2 − clearance``: the wall at the package's face. In front
    of the face the CAD cuts the window no higher (:func:`reflector_opt.cad._shapes.body_shape`),
    so an axis tilted up costs nothing more; an axis tilted down (a_z < 0) raises the
    package's back, ``sensor_depth_mm`` behind the face, by ``depth·|a_z|``, which
    :func:`plan_layout` takes off this wall. It depends on the sensors alone, not on the
    reflector or the poses: the search's cheap constraint.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    params : CadParameters, optional
        Printable-part dimensions; the paper's prototype by default. The package of a part
        that states its own replaces the parameters' (:func:`.parts.package_parameters`).

    Returns
    -------
    numpy.ndarray
        Shape (n_sensors,), mm.
    """
    params = package_parameters(params or CadParameters(), design.models)
    axes = unit(np.asarray(design.axes, dtype=float))
    # u = a × across with across = (ẑ × a)/|ẑ × a| (the strip's frame, ``_sensor_frame``):
    # |u_z| = √(a_x² + a_y²), the horizontal part of the unit axis.
    along_z = np.hypot(axes[:, 0], axes[:, 1])
    tops = (
        np.asarray(design.positions_mm, dtype=float)[:, 2] + along_z * params.sensor_length_mm / 2
    )
    return params.body_top_mm - tops - params.sensor_pocket_clearance_mm


def _plan_sensors(design, params, keepouts, envelope_radius):
    mounts = []
    for sensor in design.sensors:
        a = unit(sensor.axis)
        if abs(a[2]) > 0.5:
            raise InputError(
                f"sensor {sensor.name!r}.axis: must lie within 30° of the disk plane for the "
                "strip channel"
            )
        f = np.asarray(sensor.position_mm, dtype=float)
        pad = f - params.sensor_depth_mm * a
        pad_distance = float(-(pad @ a))
        if pad_distance + params.strip_thickness_mm > envelope_radius:
            raise InputError(
                f"sensor {sensor.name!r}: the strip behind it would stand proud of the "
                f"{2 * envelope_radius:g} mm envelope (pad at {pad_distance:.3f} mm from the axis)"
            )
        # The window reaches 0.5 mm past the wall into the cavity in front of the sensor, at its
        # centre and at its corners (a wide window's corner may meet the cavity later).
        frame = _sensor_frame(a)
        wall = _window_wall(pad, frame, params, keepouts)
        window = max(wall + 0.5, params.sensor_depth_mm + 0.5)
        mounts.append(SensorMount(sensor.name, frame, f, pad, pad_distance, window))
    return tuple(mounts)


def _wall_above_windows(design, params):
    """Thinnest body wall above the sensor windows, mm: :func:`window_wall_mm` at the face,
    less the rise of the package's back along an axis tilted down (``depth·|a_z|``)."""
    axes = unit(np.asarray(design.axes, dtype=float))
    back = params.sensor_depth_mm * np.maximum(0.0, -axes[:, 2])
    return float((window_wall_mm(design, params) - back).min())


def _window_wall(pad, frame, params, keepouts):
    """Horizontal distance from a window's centre and corners to the cavity, mm.

    The window's cross-section (the package and its pocket clearance, across and along the
    strip) has four corners; the cavity in front of them, a union of polar boxes, is as near
    as in front of the centre give or take the boxes' steps. The farthest of the five counts,
    at most :data:`WINDOW_CORNER_REACH_MM` beyond the centre's.
    """
    centre = _clearance_xy(pad[:2], keepouts)
    half_t = params.sensor_width_mm / 2.0 + params.sensor_pocket_clearance_mm
    half_u = params.sensor_length_mm / 2.0 + params.sensor_pocket_clearance_mm
    corners = np.array(
        [pad + i * half_t * frame[0] + j * half_u * frame[1] for i in (-1, 1) for j in (-1, 1)]
    )
    farthest = max(float(_clearance_xy(c[:2], keepouts)) for c in corners)
    return min(max(float(centre), farthest), float(centre) + WINDOW_CORNER_REACH_MM)


def _clearance_xy(points_xy, keepouts):
    """Smallest :meth:`PolarBox.distance_xy` of points (shape (..., 2)) to any keep-out, mm.

    Reduces over the last point axis too: shape (..., n, 2) gives shape (...).
    """
    points = np.asarray(points_xy, dtype=float)
    distances = np.stack([k.distance_xy(points) for k in keepouts])
    return distances.min(axis=(0, -1)) if points.ndim > 1 else distances.min(axis=0)


def _tendon_clearance(params, first_azimuth_deg, keepouts):
    """Ligament between the tendon holes and the swept space, mm (negative: they cut it).

    ``first_azimuth_deg`` may be an array of candidate azimuths; the result has its shape. The
    three holes' centres lie at 120° on the tendon circle, shape
    ``shape(first_azimuth_deg) + (3, 2)``.
    """
    first = np.asarray(first_azimuth_deg, dtype=float)[..., None]
    az = np.deg2rad(first + np.array([0.0, 120.0, 240.0]))
    points = params.tendon_radius_mm * np.stack([np.cos(az), np.sin(az)], axis=-1)
    return _clearance_xy(points, keepouts) - params.tendon_hole_diameter_mm / 2.0


def _choose_tendon_azimuth(params, keepouts, patch_keepouts):
    """First tendon azimuth: the given one, or the one farthest from the swept space.

    Ties (all azimuths limited by the dome alone) go to the azimuth farthest from the
    patches.
    """
    if params.tendon_azimuth_deg is not None:
        return float(params.tendon_azimuth_deg)
    candidates = np.arange(0.0, 120.0, 0.5)
    score = np.round(_tendon_clearance(params, candidates, keepouts), 3)
    score += 1e-6 * _tendon_clearance(params, candidates, patch_keepouts)
    return float(candidates[int(np.argmax(score))])


def plan_layout(design, params=None):
    """Derive every dimension of the reflector part and the body from a design.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    params : CadParameters, optional
        Printable-part dimensions (the paper's prototype by default); those left as None
        follow the design — the named bearing's widths, the tendon circle — and a value given
        explicitly wins (:func:`.parts.design_parameters`).

    Returns
    -------
    Layout
        With the ``params`` it was laid out with. Raises
        :class:`~reflector_opt.util._errors.InputError` when the design and the parameters
        cannot make the parts at all (the bearing does not fit inside the reflector, a sensor
        sits outside the envelope, the flange would hit the body …). Walls merely too thin
        are listed and judged by :func:`reflector_opt.cad.check_printability`.
    """
    params = design_parameters(params, design)
    mech, refl = design.mechanics, design.reflector
    envelope = mech.unit_diameter_mm / 2.0
    _check_bearing_fits(design, params)
    rotations = workspace_rotations(design)
    tilt_max = float(np.degrees(np.arccos(np.clip(rotations[:, 2, 2], -1.0, 1.0))).max())
    keep = _keep_deg(params, refl.inner_radius_mm)
    band_top, patches = _plan_patches(design, params, rotations, keep)
    z = _heights(design, params, tilt_max)
    _check_patches_above_bottom(patches, z["body_bottom"])
    keepouts, patch_keepouts = _keepouts(design, params, z, band_top, patches, tilt_max, keep)
    sensors = _plan_sensors(design, params, keepouts, envelope)
    tendon_az = _choose_tendon_azimuth(params, keepouts, patch_keepouts)
    azimuths = tuple(float(relative_azimuth(tendon_az + k * 120.0, 0.0)) for k in range(3))
    reflector_walls, body_walls = _walls(design, params, z, patches, keepouts, sensors, tendon_az)
    return Layout(
        params=params,
        envelope_radius_mm=envelope,
        sphere_radius_mm=float(refl.radius_mm),
        sphere_centre_mm=tuple(float(v) for v in np.asarray(refl.centre_mm, dtype=float)),
        inner_radius_mm=float(refl.inner_radius_mm),
        lid_radius_mm=refl.inner_radius_mm + params.lid_thickness_mm,
        band_top_deg=float(band_top),
        patches=patches,
        tilt_max_deg=tilt_max,
        seat_z_mm=-params.bearing_outer_width_mm / 2.0,
        body_bottom_z_mm=z["body_bottom"],
        body_top_z_mm=z["body_top"],
        flange_z_mm=z["flange"],
        flange_top_z_mm=z["flange_top"],
        shaft_radius_mm=z["shaft_radius"],
        shaft_bottom_z_mm=z["shaft_bottom"],
        swing_radius_mm=z["swing"],
        keepouts=keepouts,
        tendon_azimuths_deg=azimuths,
        sensors=sensors,
        reflector_walls_mm=reflector_walls,
        body_walls_mm=body_walls,
        min_wall_mm=float(mech.min_wall_mm),
    )


def _keep_deg(params, inner_radius_mm):
    """The angle the body keeps out beyond the swept directions, degrees: the clearance as an
    angle at the smallest radius the body keeps out of, plus the sweep margin."""
    c = params.clearance_mm
    return params.sweep_margin_deg + math.degrees(c / (inner_radius_mm - c))


def _check_bearing_fits(design, params):
    """InputError unless the sphere holds O and the bearing, the spring gap and the neck fit
    the reflector."""
    mech, refl, c = design.mechanics, design.reflector, params.clearance_mm
    check_centre_inside(refl.radius_mm, refl.centre_mm)  # a search candidate is not checked
    outer_ring_corner = math.hypot(mech.bearing_od_mm / 2.0, params.bearing_outer_width_mm / 2.0)
    if outer_ring_corner + c > refl.inner_radius_mm + 1e-9:
        raise InputError(
            f"reflector.inner_radius_mm: {refl.inner_radius_mm:g} mm does not clear the "
            f"bearing's outer ring (corner at {outer_ring_corner:.3f} mm from O) by the "
            f"clearance {c:g} mm"
        )
    if not mech.bearing_bore_mm < params.bearing_ball_diameter_mm < mech.bearing_od_mm:
        raise InputError("cad.bearing_ball_diameter_mm: must lie between the bore and the OD")
    if mech.link_length_mm - mech.unit_height_mm <= 0:
        raise InputError("mechanics.link_length_mm: must exceed unit_height_mm (spring gap)")
    if params.neck_radius_mm >= refl.inner_radius_mm:
        raise InputError("cad.neck_radius_mm: must be smaller than the inner radius")


def _check_patches_above_bottom(patches, body_bottom_z_mm):
    """InputError when a reflecting patch hangs below the body's bottom face: the reflector
    part stays between the body's bottom and its flange's top (its printability envelope)."""
    low = min(patches, key=lambda p: p.lowest_z_mm)
    if low.lowest_z_mm < body_bottom_z_mm:
        raise InputError(
            f"reflector: sensor {low.sensor}'s patch reaches down to z = "
            f"{low.lowest_z_mm:.2f} mm, below the body's bottom at {body_bottom_z_mm:.2f} mm "
            "(mechanics.unit_height_mm)"
        )


def _heights(design, params, tilt_max):
    """Heights of the body and the flange, the shaft and the bearing's swing, mm, by name;
    InputError when the body cannot hold the bearing or the tilted flange would hit it."""
    mech, c = design.mechanics, params.clearance_mm
    body_top = params.body_top_mm
    body_bottom = body_top - (mech.unit_height_mm - params.flange_thickness_mm)
    flange_z = body_top + mech.link_length_mm - mech.unit_height_mm
    shaft_radius = (mech.bearing_bore_mm - params.shaft_clearance_mm) / 2.0
    if params.neck_radius_mm <= shaft_radius:
        raise InputError("cad.neck_radius_mm: must be larger than the shaft")
    shaft_bottom = -(params.bearing_inner_width_mm / 2.0 + params.shaft_extension_mm)
    swing = max(params.bearing_ball_diameter_mm / 2.0, math.hypot(shaft_radius, shaft_bottom))
    if body_bottom >= -(swing + c):
        raise InputError(
            "cad.body_top_mm: the body is too short to hold the bearing seat "
            f"(bottom at z = {body_bottom:.2f} mm)"
        )
    tilt = math.radians(tilt_max)
    envelope = mech.unit_diameter_mm / 2.0
    flange_gap = flange_z - (body_top * math.cos(tilt) + envelope * math.sin(tilt))
    if flange_gap < c:
        raise InputError(
            f"cad.body_top_mm: the flange tilted by {tilt_max:.1f}° would come within "
            f"{flange_gap:.2f} mm of the body's top (clearance {c:g} mm)"
        )
    return {
        "body_top": body_top,
        "body_bottom": body_bottom,
        "flange": flange_z,
        "flange_top": flange_z + params.flange_thickness_mm,
        "shaft_radius": shaft_radius,
        "shaft_bottom": shaft_bottom,
        "swing": swing,
        "pocket": design.reflector.inner_radius_mm - c - POCKET_OVERLAP_MM,
    }


def _keepouts(design, params, z, band_top, patches, tilt_max, keep):
    """The swept spaces that shape the body (those reaching below its top face), and the
    sensor patches' own; ``band_top``, ``tilt_max`` and ``keep`` in degrees."""
    refl, c = design.reflector, params.clearance_mm
    lid = refl.inner_radius_mm + params.lid_thickness_mm
    neck_elevation = math.degrees(math.acos(params.neck_radius_mm / refl.inner_radius_mm))
    neck_top = math.hypot(params.neck_radius_mm, z["flange_top"])
    dome_keepout = PolarBox(z["pocket"], lid + c, band_top - tilt_max - keep, 90.0)
    neck_keepout = PolarBox(z["pocket"], neck_top + c, neck_elevation - tilt_max - keep, 90.0)
    patch_keepouts = drop_contained([b for p in patches for b in p.swept])
    # Only what reaches below the body's top face shapes the body.
    keepouts = tuple(
        k for k in (dome_keepout, neck_keepout, *patch_keepouts) if k.lowest_z() < z["body_top"]
    )
    return keepouts, patch_keepouts


def _walls(design, params, z, patches, keepouts, sensors, tendon_az):
    """The designed walls of the reflector part and of the body, mm, by name."""
    envelope, c = design.mechanics.unit_diameter_mm / 2.0, params.clearance_mm
    tendon_outer = envelope - params.tendon_radius_mm - params.tendon_hole_diameter_mm / 2.0
    reflector_walls = {
        "reflecting shell": _shell_thickness(design, patches, envelope),
        "dome": params.lid_thickness_mm,
        "roof over the bearing": z["flange_top"] - design.reflector.inner_radius_mm,
        "flange": params.flange_thickness_mm,
        "flange outside a tendon hole": tendon_outer,
    }
    body_walls = {
        "wall outside the swept space": envelope - max(k.horizontal_extent()[1] for k in keepouts),
        "wall behind a sensor channel": min(_clearance_xy(m.pad_mm[:2], keepouts) for m in sensors),
        "wall above a sensor window": _wall_above_windows(design, params),
        "wall outside a tendon hole": tendon_outer,
        "wall between a tendon hole and the swept space": _tendon_clearance(
            params, tendon_az, keepouts
        ),
        "bearing seat bowl": z["pocket"] - (z["swing"] + c),
        "floor under the bearing": -z["body_bottom"] - (z["swing"] + c),
    }
    return reflector_walls, body_walls
