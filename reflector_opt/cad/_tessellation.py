"""Mesh resolution from a chord tolerance, and the mesh's measured deviation from a sphere.

A circle of radius R drawn as an inscribed regular n-gon deviates from the true circle most
at the middle of each chord, by the sagitta ``s = R (1 − cos(π/n))``. Asking ``s ≤ δ`` gives

    n = ⌈π / arccos(1 − δ/R)⌉,

used for every cylinder, cone and revolved profile. A flat triangle with its corners on a
sphere is farthest from the sphere at its circumcentre, by ``R (1 − cos β)`` with β the angle
its circumscribed circle subtends at the centre. manifold3d's geodesic sphere (an octahedron
refined n/4 times per edge and projected) has triangles with β up to κ·π/n, κ = 1.6525
(measured over n = 8…400: the triangles near the centre of each octant are stretched most by
the projection), so a sphere uses ``n = 4 ⌈κ π / (4 arccos(1 − δ/R))⌉`` with κ = 1.66.
"""

import math

import manifold3d as mf
import numpy as np
import trimesh

from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import MAX_CIRCLE_SEGMENTS, check_size

#: Upper bound of β·n/π over manifold3d's geodesic spheres (measured maximum 1.6525).
GEODESIC_STRETCH = 1.66


def _half_angle(radius_mm, tolerance_mm):
    if not (math.isfinite(tolerance_mm) and tolerance_mm > 0):
        raise InputError(f"tolerance: must be a positive length in mm, got {tolerance_mm}")
    if tolerance_mm >= radius_mm:
        raise InputError(
            f"tolerance: {tolerance_mm:g} mm is not smaller than the {radius_mm:g} mm radius"
        )
    return math.acos(1.0 - tolerance_mm / radius_mm)


def _segments(n, radius_mm, tolerance_mm):
    """``n`` rounded up to a multiple of 4 (at least 8), refused beyond the limit."""
    check_size(
        n,
        f"tolerance {tolerance_mm:g} mm on a {radius_mm:g} mm radius",
        MAX_CIRCLE_SEGMENTS,
        "segments per circle",
    )
    return max(8, 4 * math.ceil(n / 4))


def circle_segments(radius_mm, tolerance_mm):
    """Segments of a circle whose inscribed polygon stays within a chord tolerance.

    ``n = ⌈π / arccos(1 − δ/R)⌉``, rounded up to a multiple of 4 (so the polygon has
    vertices on both axes) and at least 8.

    Parameters
    ----------
    radius_mm : float
        Circle radius R, mm.
    tolerance_mm : float
        Largest allowed distance δ between the polygon and the circle, mm.

    Returns
    -------
    int
        Number of segments for the full circle.
    """
    half = _half_angle(radius_mm, tolerance_mm)
    return _segments(math.ceil(math.pi / half) if half > 0 else math.inf, radius_mm, tolerance_mm)


def sphere_segments(radius_mm, tolerance_mm):
    """``circular_segments`` for a manifold3d geodesic sphere within a chord tolerance.

    ``n = 4 ⌈κ π / (4 arccos(1 − δ/R))⌉`` with κ = :data:`GEODESIC_STRETCH`.

    Parameters
    ----------
    radius_mm : float
        Sphere radius R, mm.
    tolerance_mm : float
        Largest allowed distance δ between the mesh and the sphere, mm.

    Returns
    -------
    int
    """
    half = _half_angle(radius_mm, tolerance_mm)
    return _segments(
        GEODESIC_STRETCH * math.pi / half if half > 0 else math.inf, radius_mm, tolerance_mm
    )


def sphere_deviation_mm(vertices_mm, faces, centre_mm, radius_mm):
    """How far a triangle mesh lies inside and outside a sphere, measured exactly.

    A triangle's nearest point to the sphere centre (computed exactly, not sampled) gives how
    far it dips inside; its vertices give how far it bulges outside.

    Parameters
    ----------
    vertices_mm : array_like, shape (n, 3)
    faces : array_like, shape (m, 3)
        Triangles to measure (e.g. only those meant to lie on the sphere).
    centre_mm : array_like, shape (3,)
    radius_mm : float

    Returns
    -------
    (float, float)
        Largest depth inside the sphere and largest height outside it, mm (≥ 0).
    """
    v = np.asarray(vertices_mm, dtype=float) - np.asarray(centre_mm, dtype=float)
    tri = v[np.asarray(faces)]
    nearest = trimesh.triangles.closest_point(tri, np.zeros((len(tri), 3)))
    inside = radius_mm - np.linalg.norm(nearest, axis=1).min()
    outside = np.linalg.norm(tri.reshape(-1, 3), axis=1).max() - radius_mm
    return max(float(inside), 0.0), max(float(outside), 0.0)


def to_trimesh(solid):
    """A manifold3d solid as a :class:`trimesh.Trimesh` (double precision, no merging).

    Parameters
    ----------
    solid : manifold3d.Manifold

    Returns
    -------
    trimesh.Trimesh
    """
    mesh = solid.to_mesh64()
    vertices = np.asarray(mesh.vert_properties, dtype=float)[:, :3]
    faces = np.asarray(mesh.tri_verts, dtype=np.int64)
    return trimesh.Trimesh(vertices=vertices, faces=faces, process=False)


def mesh_to_manifold(mesh):
    """A :class:`trimesh.Trimesh` as a manifold3d solid (single-precision vertices, as
    :class:`manifold3d.Mesh` holds them); its status says whether the mesh is a solid.

    Parameters
    ----------
    mesh : trimesh.Trimesh

    Returns
    -------
    manifold3d.Manifold
    """
    return mf.Manifold(
        mf.Mesh(
            vert_properties=np.asarray(mesh.vertices, dtype=np.float32),
            tri_verts=np.asarray(mesh.faces, dtype=np.uint32),
        )
    )
