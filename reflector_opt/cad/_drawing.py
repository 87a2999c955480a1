"""What the pictures draw: meshes simplified and solids cut, with manifold3d.

Made in the calling process, so that the process that draws the pictures (forked while the
parts are checked, :mod:`reflector_opt.cad._background`) uses matplotlib alone: manifold3d's
thread pool does not survive a fork. Nothing here imports matplotlib.
"""

import manifold3d as mf
import numpy as np
import trimesh

from reflector_opt.cad._tessellation import mesh_to_manifold

#: A 3-D preview draws the mesh simplified to within this distance of the written one, mm
#: (a pixel of the picture is about 0.04 mm of a 26 mm part).
PREVIEW_SIMPLIFY_MM = 0.05


def simplified(mesh, tolerance_mm=PREVIEW_SIMPLIFY_MM):
    """A mesh simplified for a picture (never for a written file).

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Closed mesh, mm.
    tolerance_mm : float
        Largest distance of the simplified surface from the mesh, mm.

    Returns
    -------
    trimesh.Trimesh
        The simplified mesh; the mesh itself if manifold3d cannot take it as a solid.
    """
    solid = mesh_to_manifold(mesh)
    if solid.status() != mf.Error.NoError:
        return mesh
    simple = solid.simplify(tolerance_mm).to_mesh()
    vertices = np.asarray(simple.vert_properties, dtype=float)[:, :3]
    return trimesh.Trimesh(vertices, np.asarray(simple.tri_verts), process=False)


def section_polygons(solid, azimuth_deg):
    """Outline of a solid in the half-plane through the z axis at an azimuth.

    The solid is turned by −azimuth about z, then (x, y, z) → (x, z, −y), so the section
    plane becomes z = 0 with coordinates (distance along the azimuth, height).

    Parameters
    ----------
    solid : manifold3d.Manifold
    azimuth_deg : float

    Returns
    -------
    list of numpy.ndarray
        Closed polygons, each of shape (n, 2), mm.
    """
    turned = solid.rotate((0.0, 0.0, -azimuth_deg))
    onto_plane = [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, -1.0, 0.0, 0.0]]
    polygons = turned.transform(onto_plane).slice(0.0).to_polygons()
    return [np.asarray(poly, dtype=float) for poly in polygons]
