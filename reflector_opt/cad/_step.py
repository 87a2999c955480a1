"""STEP files of the printed parts: exact B-rep solids built with build123d (optional).

The meshes of :mod:`reflector_opt.cad._solids` are for printing; a CAD program wants the true
surfaces: spheres, cones, cylinders and planes that it can measure, fillet and modify. This
module builds the two printed parts from the description the meshes are built from
(:mod:`reflector_opt.cad._shapes`), node for node, on OpenCASCADE's exact primitives through
build123d (:func:`to_solid`), checks each against its mesh (:func:`mesh_disagreement`) and
writes it as one solid in a STEP file (AP214, millimetres).

build123d is an optional dependency: ``pip install 'reflector-opt[step]'``. Without it,
:func:`step_available` is False and :func:`build_step_parts` raises
:class:`~reflector_opt.util._errors.InputError` saying how to install it.
"""

import importlib
import math
import operator
import warnings
from functools import reduce, singledispatch
from pathlib import Path

import manifold3d as mf
import trimesh

from reflector_opt.cad import _shapes as shapes
from reflector_opt.cad._solids import SOLIDS, build_parts
from reflector_opt.cad._tessellation import mesh_to_manifold
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import atomic_path

#: The printed parts a STEP file is written for.
STEP_PARTS = tuple(shapes.PRINTED_SHAPES)
#: Largest difference between an exact solid's volume and its mesh's, as a fraction of the
#: mesh's.
VOLUME_TOLERANCE = 0.005
#: Coarsest chord tolerance of the meshes an exact solid is compared with, mm: the meshes'
#: volumes then lie within 0.2 % of the exact solids' (inscribed, they are a little smaller).
CHECK_TOLERANCE_MM = 0.01
#: Largest volume an exact solid may share with a solid that turns relative to it, mm³
#: (they stand a running clearance apart: any overlap is a wrong solid).
OVERLAP_LIMIT_MM3 = 1e-3
#: Time stamp in every STEP file's header (ISO 8601): the same solid, the same file.
STEP_TIMESTAMP = "1970-01-01T00:00:00"
#: Angular deflection of the triangulation an exact solid is compared by, radians.
ANGULAR_TOLERANCE_RAD = 0.1
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


def _xz(radius, elevation_deg):
    """The point at a distance and elevation about O in the x–z plane (the profile plane)."""
    e = math.radians(elevation_deg)
    return (radius * math.cos(e), 0.0, radius * math.sin(e))


def _arc(bd, radius, e0, e1):
    """The arc of a circle about O in the x–z plane from elevation e0 to e1 (degrees)."""
    ends = (e0, 0.5 * (e0 + e1), e1)
    return bd.ThreePointArc(*(_xz(radius, e) for e in ends))


@singledispatch
def to_solid(shape):
    """The exact build123d solid of a node of :mod:`reflector_opt.cad._shapes`.

    Spheres, cylinders, boxes, wedges and revolved profiles bounded by true circular arcs
    are combined by OpenCASCADE's booleans: a union fuses its shapes in one operation and a
    difference cuts all its cuts at once.

    Parameters
    ----------
    shape : reflector_opt.cad._shapes node

    Returns
    -------
    build123d.Shape
    """
    raise TypeError(f"no exact solid for {type(shape).__name__}")


@to_solid.register
def _(shape: shapes.Sphere):
    bd = _bd()
    return bd.Pos(*shape.centre_mm) * bd.Sphere(shape.radius_mm)


@to_solid.register
def _(shape: shapes.Cylinder):
    bd = _bd()
    align = (bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN)
    solid = bd.Cylinder(shape.radius_mm, shape.z1_mm - shape.z0_mm, align=align)
    return bd.Pos(*shape.centre_xy_mm, shape.z0_mm) * solid


@to_solid.register
def _(shape: shapes.Block):
    bd = _bd()
    plane = bd.Plane(origin=shape.centre_mm, x_dir=shape.frame[0], z_dir=shape.frame[2])
    return plane * bd.Box(*shape.size_mm)


@to_solid.register
def _(shape: shapes.Sector):
    bd = _bd()
    a = [math.radians(v) for v in (shape.a0_deg, 0.5 * (shape.a0_deg + shape.a1_deg), shape.a1_deg)]
    rim = [(shape.reach_mm * math.cos(v), shape.reach_mm * math.sin(v), 0.0) for v in a]
    origin = (0.0, 0.0, 0.0)
    wire = bd.Wire([bd.Line(origin, rim[0]), bd.ThreePointArc(*rim), bd.Line(rim[2], origin)])
    solid = bd.Solid.extrude(bd.Face(wire), (0.0, 0.0, shape.z1_mm - shape.z0_mm))
    return bd.Pos(0.0, 0.0, shape.z0_mm) * solid


@to_solid.register
def _(shape: shapes.Revolved):
    bd = _bd()
    # The (ρ, z) profile in the x–z plane: up the outer steps (an arc each, a radial line
    # before each), back along the inner arc (or to O, where r0 = 0).
    e0, e1 = shape.elevation_range_deg
    corner = _xz(shape.r0_mm, e0)
    edges = []
    for lo, hi, radius in shape.steps:
        edges += [bd.Line(corner, _xz(radius, lo)), _arc(bd, radius, lo, hi)]
        corner = _xz(radius, hi)
    edges.append(bd.Line(corner, _xz(shape.r0_mm, e1)))
    if shape.r0_mm > 0:
        edges.append(_arc(bd, shape.r0_mm, e1, e0))
    face = bd.Face(bd.Wire(edges))
    if shape.a0_deg is None:
        return bd.Solid.revolve(face, 360.0, bd.Axis.Z)
    solid = bd.Solid.revolve(face, shape.a1_deg - shape.a0_deg, bd.Axis.Z)
    return bd.Rot(0.0, 0.0, shape.a0_deg) * solid


@to_solid.register
def _(shape: shapes.SweptSpace):
    return to_solid(shapes.Union(shape.pieces()))


@to_solid.register
def _(shape: shapes.Slab):
    bd = _bd()
    solid = to_solid(shape.shape)
    if shape.z_min_mm is not None:
        solid = solid.split(bd.Plane.XY.offset(shape.z_min_mm), keep=bd.Keep.TOP)
    if shape.z_max_mm is not None:
        solid = solid.split(bd.Plane.XY.offset(shape.z_max_mm), keep=bd.Keep.BOTTOM)
    return solid


@to_solid.register
def _(shape: shapes.Union):
    first, *others = (to_solid(s) for s in shape.shapes)
    return first.fuse(*others)


@to_solid.register
def _(shape: shapes.Intersection):
    return reduce(operator.and_, (to_solid(s) for s in shape.shapes))


@to_solid.register
def _(shape: shapes.Difference):
    return to_solid(shape.base).cut(*(to_solid(s) for s in shape.cuts))


def exact_part(name, layout):
    """A printed part as one exact solid, built from its description.

    The booleans are not tidied one by one; the finished solid's faces that share a surface
    are merged once at the end (best effort: where OpenCASCADE cannot merge them the solid
    keeps them split, which changes no point of it).

    Parameters
    ----------
    name : {"reflector", "body"}
    layout : reflector_opt.design._layout.Layout

    Returns
    -------
    build123d.Solid

    Raises
    ------
    reflector_opt.util._errors.InputError
        build123d is not installed, or the part does not come out as one valid solid.
    """
    bd = _bd()
    with bd.SkipClean():
        shape = to_solid(shapes.PRINTED_SHAPES[name](layout))
    count = len(shape.solids())
    if count != 1 or not shape.is_valid:
        raise InputError(
            f"{name}: the STEP solid came out as {count} solid(s)"
            + ("" if shape.is_valid else ", not valid")
            + "; export the mesh files instead"
        )
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Unable to clean")
        solid = shape.solids()[0].clean()
    solid.label = name  # the name in the STEP file's header
    return solid


def triangulated(solid, tolerance_mm):
    """An exact solid's triangulation as a manifold3d solid (its status an error if not closed).

    Parameters
    ----------
    solid : build123d.Solid
    tolerance_mm : float
        Largest distance of the triangles from the true surface, mm.

    Returns
    -------
    manifold3d.Manifold
    """
    vertices, triangles = solid.tessellate(tolerance_mm, ANGULAR_TOLERANCE_RAD)
    # every face is triangulated apart: merge the vertices its neighbours share
    mesh = trimesh.Trimesh([tuple(v) for v in vertices], triangles, process=True)
    return mesh_to_manifold(mesh)


def _overlaps(name, triangulation, reference):
    """Lines for each solid turning relative to the part that the triangulation overlaps."""
    turning = name in reference.rotating
    problems = []
    for other in SOLIDS:
        if (other in reference.rotating) == turning:
            continue
        overlap = (triangulation ^ getattr(reference, other)).volume()
        if overlap > OVERLAP_LIMIT_MM3:
            problems.append(
                f"{name}: the STEP solid overlaps the {other.replace('_', ' ')} by "
                f"{overlap:.3f} mm³ at zero pose"
            )
    return problems


def mesh_disagreement(name, volume_mm3, triangulation, reference):
    """How an exact solid of a printed part differs from the part's mesh, in words.

    The exact solid and the mesh are built from one description
    (:mod:`reflector_opt.cad._shapes`), so they must agree: the volumes within
    :data:`VOLUME_TOLERANCE` of the mesh's; the exact solid's triangulation closed, with as
    many handles (genus: through-holes such as the tendon holes) as the mesh; and at zero
    pose it may share no more than :data:`OVERLAP_LIMIT_MM3` with any solid that turns
    relative to the part (the body with the reflector part and the inner ring; the reflector
    part with the body, the outer ring and the sensors), which stand a running clearance
    apart.

    Parameters
    ----------
    name : {"reflector", "body"}
    volume_mm3 : float
        Volume of the exact solid, mm³.
    triangulation : manifold3d.Manifold
        The exact solid triangulated (:func:`triangulated`).
    reference : reflector_opt.cad._solids.Parts
        The meshes of every solid, built from the same layout.

    Returns
    -------
    list of str
        One line per disagreement, each starting with the part's name; empty when they
        agree.
    """
    problems = []
    mesh = getattr(reference, name)
    difference = abs(volume_mm3 / mesh.volume() - 1.0)
    if difference > VOLUME_TOLERANCE:
        problems.append(
            f"{name}: the STEP solid's volume {volume_mm3:.1f} mm³ differs from the mesh's "
            f"{mesh.volume():.1f} mm³ by {difference:.1%} (at most {VOLUME_TOLERANCE:.1%})"
        )
    if triangulation.is_empty() or triangulation.status() != mf.Error.NoError:
        return [*problems, f"{name}: the STEP solid's triangulation is not a closed solid"]
    if triangulation.genus() != mesh.genus():
        problems.append(
            f"{name}: the STEP solid has genus {triangulation.genus()}, "
            f"the mesh {mesh.genus()} (a hole too many or missing)"
        )
    return problems + _overlaps(name, triangulation, reference)


def build_step_parts(design, layout, parts=STEP_PARTS, reference=None):
    """The printed parts of a layout as exact solids, each checked against its mesh.

    Each part is built from its description (:func:`exact_part`) and must agree with the mesh
    built from the same description (:func:`mesh_disagreement`), or it is refused. The meshes
    compared with are ``reference`` when it holds the parts and is at least as fine as
    :data:`CHECK_TOLERANCE_MM`, else meshes built at that tolerance.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    layout : reflector_opt.design._layout.Layout
        From :func:`~reflector_opt.design._layout.plan_layout`.
    parts : iterable of {"reflector", "body"}
    reference : reflector_opt.cad._solids.Parts, optional
        The meshes of this layout (:func:`~reflector_opt.cad._solids.build_parts`).

    Returns
    -------
    dict of str to build123d.Solid

    Raises
    ------
    reflector_opt.util._errors.InputError
        build123d is not installed, or a part does not come out as one valid solid that
        agrees with its mesh (the message names each disagreement).
    """
    unknown = sorted(set(parts) - set(STEP_PARTS))
    if unknown:
        raise InputError(f"part: STEP is written for {', '.join(STEP_PARTS)}, got {unknown}")
    if (
        reference is None
        or reference.tolerance_mm > CHECK_TOLERANCE_MM
        or any(getattr(reference, name).is_empty() for name in parts)
    ):
        reference = build_parts(design, layout, CHECK_TOLERANCE_MM)
    solids = {}
    for name in parts:
        solid = exact_part(name, layout)
        mesh = triangulated(solid, reference.tolerance_mm)
        problems = mesh_disagreement(name, solid.volume, mesh, reference)
        if problems:
            raise InputError("; ".join(problems) + "; no STEP file is written")
        solids[name] = solid
    return solids


def write_step(path, solid):
    """Write one solid as a STEP file (millimetres), atomically.

    The header carries the solid's label as the model's name and a fixed time stamp
    (:data:`STEP_TIMESTAMP`), so writing the same solid again gives the same file.

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
        if not bd.export_step(solid, tmp, unit=bd.Unit.MM, timestamp=STEP_TIMESTAMP):
            raise InputError(f"cannot write {path}: the STEP writer failed")
    return path
