"""STEP files of the printed parts: exact B-rep solids built with build123d (optional).

The meshes of :mod:`reflector_opt.cad.solids` are for printing; a CAD program wants the true
surfaces: spheres, cones, cylinders and planes that it can measure, fillet and modify. This
module builds the same two parts from the same :class:`~reflector_opt.design.layout.Layout`
(every dimension, polar box, patch and sensor mount comes from it, none is repeated here)
by the same constructive steps as :func:`~reflector_opt.cad.solids.reflector_solid` and
:func:`~reflector_opt.cad.solids.body_solid`, on OpenCASCADE's exact primitives through
build123d, and writes each as one solid in a STEP file (AP214, millimetres).

build123d is an optional dependency: ``pip install 'reflector-opt[step]'``. Without it,
:func:`step_available` is False and :func:`build_step_parts` raises
:class:`~reflector_opt.util.errors.InputError` saying how to install it.
"""

from __future__ import annotations

import importlib
import math
from pathlib import Path

import numpy as np

from reflector_opt.design.polar import PolarBox
from reflector_opt.util.errors import InputError
from reflector_opt.util.fileio import atomic_path

__all__ = ["STEP_PARTS", "build_step_parts", "step_available", "write_step"]

#: The printed parts a STEP file is written for.
STEP_PARTS = ("reflector", "body")
#: What to install for STEP export.
_INSTALL = "pip install 'reflector-opt[step]'"


def step_available():
    """True when build123d, the optional dependency of STEP export, can be imported."""
    try:
        _bd()
    except InputError:
        return False
    return True


def _bd():
    try:
        return importlib.import_module("build123d")
    except ImportError:
        raise InputError(f"STEP export needs build123d: {_INSTALL}") from None


def _point(rho, z):
    """A point of the (ρ, z) half-plane as a 3-D point in the x–z plane."""
    return (float(rho), 0.0, float(z))


def _arc(bd, radius, e0, e1):
    """The arc of a circle about O in the x–z plane from elevation e0 to e1 (degrees)."""
    ends = [math.radians(e) for e in (e0, 0.5 * (e0 + e1), e1)]
    points = [_point(radius * math.cos(e), radius * math.sin(e)) for e in ends]
    return bd.ThreePointArc(*points)


def _sphere(bd, radius, centre=(0.0, 0.0, 0.0)):
    return bd.Pos(*(float(c) for c in centre)) * bd.Sphere(float(radius))


def _cylinder(bd, radius, z0, z1, centre_xy=(0.0, 0.0)):
    align = (bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN)
    solid = bd.Cylinder(float(radius), float(z1 - z0), align=align)
    return bd.Pos(float(centre_xy[0]), float(centre_xy[1]), float(z0)) * solid


def polar_solid(box):
    """Exact solid of a :class:`~reflector_opt.design.polar.PolarBox`.

    The (ρ, z) profile — the annular sector between the radii and elevations, bounded by
    true circular arcs — is revolved about z over the box's azimuth range (all around if it
    has none), as :func:`reflector_opt.cad.solids.polar_solid` does with polygons.

    Parameters
    ----------
    box : PolarBox

    Returns
    -------
    build123d.Solid
    """
    bd = _bd()
    e0, e1 = max(box.e0, -90.0), min(box.e1, 90.0)
    outer = _arc(bd, box.r1, e0, e1)
    start, end = outer @ 0, outer @ 1
    if box.r0 > 0:
        inner = _arc(bd, box.r0, e1, e0)
        edges = [outer, bd.Line(end, inner @ 0), inner, bd.Line(inner @ 1, start)]
    else:
        edges = [outer, bd.Line(end, (0.0, 0.0, 0.0)), bd.Line((0.0, 0.0, 0.0), start)]
    face = bd.Face(bd.Wire(edges))
    if box.a0 is None:
        return bd.Solid.revolve(face, 360.0, bd.Axis.Z)
    solid = bd.Solid.revolve(face, float(box.a1 - box.a0), bd.Axis.Z)
    return bd.Rot(0.0, 0.0, float(box.a0)) * solid


def _sector_prism(bd, a0, a1, reach, z0, z1):
    """All points with azimuth in [a0, a1] (degrees, a1 − a0 < 180) and z0 ≤ z ≤ z1."""
    a = [math.radians(v) for v in (a0, 0.5 * (a0 + a1), a1)]
    rim = [(reach * math.cos(v), reach * math.sin(v), 0.0) for v in a]
    origin = (0.0, 0.0, 0.0)
    wire = bd.Wire([bd.Line(origin, rim[0]), bd.ThreePointArc(*rim), bd.Line(rim[2], origin)])
    solid = bd.Solid.extrude(bd.Face(wire), (0.0, 0.0, float(z1 - z0)))
    return bd.Pos(0.0, 0.0, float(z0)) * solid


def _box(bd, frame, centre, size):
    """Box with edges along the rows of ``frame`` (3×3), centred at ``centre``."""
    frame = np.asarray(frame, dtype=float)
    plane = bd.Plane(
        origin=tuple(map(float, centre)),
        x_dir=tuple(map(float, frame[0])),
        z_dir=tuple(map(float, frame[2])),
    )
    return plane * bd.Box(*(float(s) for s in size))


def _union(shapes):
    total = shapes[0]
    for shape in shapes[1:]:
        total = total + shape
    return total


def _tendon_holes(bd, layout):
    p = layout.params
    z0, z1 = layout.body_bottom_z_mm - 1.0, layout.flange_top_z_mm + 1.0
    holes = []
    for az in np.deg2rad(layout.tendon_azimuths_deg):
        xy = (p.tendon_radius_mm * math.cos(az), p.tendon_radius_mm * math.sin(az))
        holes.append(_cylinder(bd, p.tendon_hole_diameter_mm / 2.0, z0, z1, xy))
    return holes


def _channels(bd, layout):
    """Vertical channel for the strip behind each sensor, through body and flange."""
    p = layout.params
    z0, z1 = layout.body_bottom_z_mm - 1.0, layout.flange_top_z_mm + 1.0
    cuts = []
    for m in layout.sensors:
        depth = layout.envelope_radius_mm + 1.0 - m.pad_distance_mm
        centre = m.pad_mm - m.frame[2] * depth / 2.0
        centre[2] = 0.5 * (z0 + z1)
        height = (z1 - z0) / abs(m.frame[1, 2])
        cuts.append(_box(bd, m.frame, centre, (p.strip_width_mm, height, depth)))
    return cuts


def _windows(bd, layout):
    p = layout.params
    g = 2.0 * p.sensor_pocket_clearance_mm
    cuts = []
    for m in layout.sensors:
        length = m.window_length_mm + 0.1
        centre = m.pad_mm + m.frame[2] * (length / 2.0 - 0.1)
        size = (p.sensor_width_mm + g, p.sensor_length_mm + g, length)
        cuts.append(_box(bd, m.frame, centre, size))
    return cuts


def reflector_step_solid(layout):
    """The reflector part at zero pose as an exact solid (see the module docstring).

    Parameters
    ----------
    layout : reflector_opt.design.layout.Layout

    Returns
    -------
    build123d.Part
    """
    bd = _bd()
    p = layout.params
    reach = 4.0 * layout.envelope_radius_mm + 4.0 * layout.flange_top_z_mm
    outer = _sphere(bd, layout.sphere_radius_mm, layout.sphere_centre_mm)
    lid = _sphere(bd, layout.lid_radius_mm)
    below_band_top = polar_solid(PolarBox(0.0, reach, -90.0, layout.band_top_deg))
    patch_space = outer & (below_band_top + lid)
    pieces = []
    for patch in layout.patches:
        sector = _sector_prism(bd, *patch.azimuth_deg, reach, -reach, reach)
        below = polar_solid(PolarBox(0.0, reach, -90.0, patch.elevation_deg[0]))
        pieces.append((patch_space & sector) - below)
    pieces.append(lid - below_band_top)
    neck_top = layout.flange_z_mm + p.flange_thickness_mm / 2.0
    pieces.append(_cylinder(bd, p.neck_radius_mm, 0.0, neck_top))
    pieces.append(
        _cylinder(bd, layout.envelope_radius_mm, layout.flange_z_mm, layout.flange_top_z_mm)
    )
    solid = _union(pieces) - _sphere(bd, layout.inner_radius_mm)
    solid = solid + _cylinder(bd, layout.shaft_radius_mm, layout.shaft_bottom_z_mm, neck_top)
    envelope = _cylinder(
        bd,
        layout.envelope_radius_mm,
        layout.shaft_bottom_z_mm - 1.0,
        layout.flange_top_z_mm + 1.0,
    )
    return (solid & envelope) - _union(_tendon_holes(bd, layout) + _channels(bd, layout))


def body_step_solid(layout):
    """The body at the joint as an exact solid (see the module docstring).

    Parameters
    ----------
    layout : reflector_opt.design.layout.Layout

    Returns
    -------
    build123d.Part
    """
    bd = _bd()
    c = layout.params.clearance_mm
    blank = _cylinder(bd, layout.envelope_radius_mm, layout.body_bottom_z_mm, layout.body_top_z_mm)
    pocket = _sphere(bd, layout.bearing_pocket_radius_mm).split(
        bd.Plane.XY.offset(layout.seat_z_mm), keep=bd.Keep.TOP
    )
    cuts = [
        pocket,
        _sphere(bd, layout.swing_radius_mm + c),
        *(polar_solid(box) for box in layout.keepouts),
        *_windows(bd, layout),
        *_channels(bd, layout),
        *_tendon_holes(bd, layout),
    ]
    return blank - _union(cuts)


def build_step_parts(layout, parts=STEP_PARTS):
    """The printed parts of a layout as exact solids.

    Parameters
    ----------
    layout : reflector_opt.design.layout.Layout
        From :func:`~reflector_opt.design.layout.plan_layout`.
    parts : iterable of {"reflector", "body"}

    Returns
    -------
    dict of str to build123d.Part
        Each one valid solid.

    Raises
    ------
    reflector_opt.util.errors.InputError
        build123d is not installed, or a part does not come out as one valid solid.
    """
    builders = {"reflector": reflector_step_solid, "body": body_step_solid}
    unknown = sorted(set(parts) - set(builders))
    if unknown:
        raise InputError(f"part: STEP is written for {', '.join(STEP_PARTS)}, got {unknown}")
    solids = {}
    for name in parts:
        solid = builders[name](layout)
        count = len(solid.solids())
        if count != 1 or not solid.is_valid:
            raise InputError(
                f"{name}: the exact solid came out as {count} solid(s)"
                + ("" if solid.is_valid else ", not valid")
                + "; export the mesh files instead"
            )
        solids[name] = solid.solids()[0]
    return solids


def write_step(path, solid):
    """Write one solid as a STEP file (millimetres), atomically.

    Parameters
    ----------
    path : str or pathlib.Path
    solid : build123d.Solid

    Returns
    -------
    pathlib.Path
    """
    bd = _bd()
    path = Path(path)
    with atomic_path(path, suffix=".step") as tmp:
        if not bd.export_step(solid, tmp, unit=bd.Unit.MM):
            raise InputError(f"cannot write {path}: the STEP writer failed")
    return path
