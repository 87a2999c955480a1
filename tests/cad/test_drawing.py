"""What the pictures draw (cad.drawing): meshes simplified, solids cut through the z axis."""

import manifold3d as mf
import numpy as np
import pytest
import trimesh

from reflector_opt.cad import to_trimesh
from reflector_opt.cad._drawing import section_polygons, simplified


def test_a_simplified_sphere_stays_within_the_tolerance():
    mesh = to_trimesh(mf.Manifold.sphere(9.0, 256))
    radius = np.linalg.norm(mesh.vertices, axis=1)
    chord = 9.0 - radius.min()  # the inscribed mesh's own depth below the sphere
    simple = simplified(mesh, 0.05)
    assert len(simple.faces) < len(mesh.faces) / 2
    distance = np.linalg.norm(simple.vertices, axis=1)
    assert distance.max() <= 9.0 + 0.05 + 1e-6 and distance.min() >= 9.0 - chord - 0.05 - 1e-6
    assert simple.volume == pytest.approx(mesh.volume, rel=0.02)


def test_a_mesh_that_is_no_solid_is_drawn_as_it_is():
    box = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    open_box = trimesh.Trimesh(box.vertices, box.faces[:-2], process=False)  # one side open
    assert simplified(open_box) is open_box


def test_sections_of_a_box_by_hand():
    # A 2 mm cube centred at (0, 5, 0): the plane through z at azimuth 0 (the x-z plane) misses
    # it; at azimuth 90° it cuts the square 4 ≤ along ≤ 6, −1 ≤ height ≤ 1.
    box = mf.Manifold.cube((2.0, 2.0, 2.0), center=True).translate((0.0, 5.0, 0.0))
    assert section_polygons(box, 0.0) == []
    (square,) = section_polygons(box, 90.0)
    np.testing.assert_allclose(square.min(axis=0), [4.0, -1.0], atol=1e-6)
    np.testing.assert_allclose(square.max(axis=0), [6.0, 1.0], atol=1e-6)
    # A box above the plane z = 0 keeps its height: up is up in the section.
    high = mf.Manifold.cube((2.0, 2.0, 2.0)).translate((3.0, -1.0, 4.0))
    (section,) = section_polygons(high, 0.0)
    np.testing.assert_allclose(section.min(axis=0), [3.0, 4.0], atol=1e-6)
    np.testing.assert_allclose(section.max(axis=0), [5.0, 6.0], atol=1e-6)
