"""The printable solids (cad.solids): the reflector part's surface against its sphere."""

import numpy as np

from reflector_opt.cad import to_trimesh
from reflector_opt.cad.tessellation import sphere_deviation_mm
from tests.cad.designs import COARSE


def test_reflecting_surface_of_the_part_within_tolerance(built):
    design, layout, parts, _ = built
    mesh = to_trimesh(parts.reflector)
    centre = np.asarray(design.reflector.centre_mm)
    radius = design.reflector.radius_mm
    corners = mesh.vertices[mesh.faces]
    radial = mesh.triangles_center - centre
    elevation = np.degrees(
        np.arcsin(mesh.triangles_center[:, 2] / np.linalg.norm(mesh.triangles_center, axis=1))
    )
    on_sphere = (
        np.all(np.abs(np.linalg.norm(corners - centre, axis=-1) - radius) <= COARSE, axis=1)
        & (np.einsum("ij,ij->i", mesh.face_normals, radial) > 0.99 * np.linalg.norm(radial, axis=1))
        & (elevation < layout.band_top_deg)  # the band; the dome above may stand proud of it
    )
    assert on_sphere.sum() > 100
    inside, outside = sphere_deviation_mm(mesh.vertices, mesh.faces[on_sphere], centre, radius)
    assert inside <= COARSE and outside < 1e-9
