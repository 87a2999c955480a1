"""STEP export: exact solids built from the parts' description, checked against the meshes.

The tests that build solids need the optional build123d (``pip install '.[step]'``) and skip
without it; the refusal without it, and the check of a solid against the meshes (on
manifold3d solids standing in for triangulated STEP solids), are tested either way.
"""

import sys

import manifold3d as mf
import numpy as np
import pytest
import trimesh

import reflector_opt.cad._step as step
from reflector_opt.cad import _shapes as shapes
from reflector_opt.cad import build_parts, export_parts, plan_layout
from reflector_opt.cad._solids import to_manifold
from reflector_opt.cad._step import (
    OVERLAP_LIMIT_MM3,
    VOLUME_TOLERANCE,
    build_step_parts,
    mesh_disagreement,
    step_available,
)
from reflector_opt.cli import main
from reflector_opt.util._errors import InputError
from tests.cad.designs import DESIGN_A, designs

#: Chord tolerance of the meshes compared with the STEP solids, mm.
TOLERANCE = 0.01
#: Chord tolerance of the STEP solids' own triangulation in the comparison, mm.
STEP_TESSELLATION = 0.002
#: Every test design, by name.
DESIGNS = designs()


@pytest.fixture(scope="module")
def bd():
    return pytest.importorskip("build123d")


@pytest.fixture(scope="module")
def exported(bd, tmp_path_factory):
    out = tmp_path_factory.mktemp("step")
    report = export_parts(DESIGN_A, out, tolerance_mm=TOLERANCE, preview=False, step=True)
    return out, report


def _read_back(bd, path):
    solids = bd.import_step(path).solids()
    assert len(solids) == 1  # one solid per part
    return solids[0]


def _as_manifold(bd, solid):
    """The STEP solid triangulated finely, as a manifold3d solid."""
    vertices, triangles = solid.tessellate(STEP_TESSELLATION, 0.1)
    mesh = trimesh.Trimesh(np.array([tuple(v) for v in vertices]), np.array(triangles))
    mesh.merge_vertices()
    manifold = mf.Manifold(
        mf.Mesh(
            vert_properties=np.asarray(mesh.vertices, dtype=np.float32),
            tri_verts=np.asarray(mesh.faces, dtype=np.uint32),
        )
    )
    assert manifold.status() == mf.Error.NoError
    return manifold


@pytest.mark.parametrize("part", ["reflector", "body"])
def test_step_reads_back_as_the_mesh_solid(bd, exported, part):
    out, report = exported
    assert report["files"][part]["step"] == f"{part}.step"  # named within the folder
    solid = _read_back(bd, out / f"{part}.step")
    assert solid.is_valid
    mesh = trimesh.load(out / f"{part}.stl")
    # every point of the true surface lies within δ of the mesh: the two volumes differ by at
    # most δ times the surface area, and so does the region where the two solids differ
    bound = TOLERANCE * mesh.area
    assert abs(solid.volume - mesh.volume) <= bound
    step = _as_manifold(bd, solid)
    meshed = mf.Manifold(
        mf.Mesh(
            vert_properties=np.asarray(mesh.vertices, dtype=np.float32),
            tri_verts=np.asarray(mesh.faces, dtype=np.uint32),
        )
    )
    apart = (step - meshed).volume() + (meshed - step).volume()
    assert apart <= (TOLERANCE + STEP_TESSELLATION) * mesh.area
    box = solid.bounding_box()
    assert np.allclose(tuple(box.min), mesh.bounds[0], atol=TOLERANCE)
    assert np.allclose(tuple(box.max), mesh.bounds[1], atol=TOLERANCE)


def test_step_surfaces_are_exact(bd, exported):
    out, _ = exported
    reflector = _read_back(bd, out / "reflector.step")
    refl = DESIGN_A.reflector
    spheres = [
        f for f in reflector.faces() if f.geom_type == bd.GeomType.SPHERE and f.radius == 9.0
    ]
    assert len(spheres) >= 2  # a reflecting patch per sensor, on the Eq 3 sphere itself
    for face in spheres:
        for u, v in ((0.1, 0.2), (0.5, 0.5), (0.9, 0.7)):
            point = np.array(tuple(face.position_at(u, v)))
            assert np.linalg.norm(point - refl.centre_mm) == pytest.approx(9.0, abs=1e-9)
    body = _read_back(bd, out / "body.step")
    hole = plan_layout(DESIGN_A).params.tendon_hole_diameter_mm / 2.0
    holes = [
        f
        for f in body.faces()
        if f.geom_type == bd.GeomType.CYLINDER and f.radius == pytest.approx(hole)
    ]
    assert len(holes) == 3  # the three tendon holes, true cylinders


def test_export_command_writes_step(bd, tmp_path, capsys):
    design = tmp_path / "a.json"
    DESIGN_A.save(design)
    out = tmp_path / "out"
    args = ["export", str(design), "-o", str(out), "--part", "reflector", "--format", "step"]
    assert main([*args, "--chord-tolerance", "0.05", "--no-preview"]) == 0
    assert sorted(p.name for p in out.iterdir()) == [
        "cad_report.json",
        "manifest.json",
        "reflector.3mf",
        "reflector.step",
        "reflector.stl",
    ]
    assert "reflector.step" in capsys.readouterr().out
    assert _read_back(bd, out / "reflector.step").is_valid


def test_without_build123d_step_is_refused_and_nothing_written(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "build123d", None)  # import build123d fails
    assert not step_available()
    with pytest.raises(InputError, match=r"pip install 'reflector-opt\[step\]'"):
        export_parts(DESIGN_A, tmp_path, parts=("reflector",), step=True)
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(InputError, match="needs build123d"):
        build_step_parts(DESIGN_A, plan_layout(DESIGN_A))


@pytest.mark.parametrize("name", list(DESIGNS))
def test_every_design_gives_step_solids_that_agree_with_the_meshes(bd, name):
    """The optimiser's designs, their variants and built units: each STEP solid is one valid
    solid within 0.5 % of its mesh's volume, with its holes, clear of the turning parts."""
    design = DESIGNS[name]
    layout = plan_layout(design)
    meshes = build_parts(design, layout, TOLERANCE)
    solids = build_step_parts(design, layout, reference=meshes)  # checks each, or refuses
    for part, solid in solids.items():
        assert solid.is_valid
        mesh = getattr(meshes, part)
        assert abs(solid.volume / mesh.volume() - 1.0) <= VOLUME_TOLERANCE


def _without_swept_space(name, layout):
    """The issue's defect: a body from which the swept space did not come off."""
    body = shapes.body_shape(layout)
    kept = tuple(c for c in body.cuts if not isinstance(c, shapes.SweptSpace))
    assert len(kept) == len(body.cuts) - 1
    return step.to_solid(shapes.Difference(body.base, kept)).solids()[0]


def test_a_step_solid_unlike_its_mesh_is_refused_and_nothing_written(bd, tmp_path, monkeypatch):
    monkeypatch.setattr(step, "exact_part", _without_swept_space)
    with pytest.raises(InputError) as refused:
        export_parts(DESIGN_A, tmp_path, parts=("body",), preview=False, step=True)
    message = str(refused.value)
    assert message.startswith("body: the STEP solid's volume")
    assert "overlaps the reflector by" in message and message.endswith("no STEP file is written")
    assert list(tmp_path.iterdir()) == []


# --- the check of an exact solid against the meshes, without build123d ---------------------

COARSE = 0.05


@pytest.fixture(scope="module")
def meshes():
    layout = plan_layout(DESIGN_A)
    return layout, build_parts(DESIGN_A, layout, COARSE)


def test_the_mesh_itself_agrees(meshes):
    _, parts = meshes
    for name in ("reflector", "body"):
        solid = getattr(parts, name)
        assert mesh_disagreement(name, solid.volume(), solid, parts) == []


def test_a_solid_larger_than_its_mesh_is_named(meshes):
    _, parts = meshes
    volume = parts.body.volume()
    larger = volume * (1.0 + 1.5 * VOLUME_TOLERANCE)
    assert mesh_disagreement("body", larger, parts.body, parts) == [
        f"body: the STEP solid's volume {larger:.1f} mm³ differs from the mesh's {volume:.1f} "
        "mm³ by 0.8% (at most 0.5%)"
    ]


def test_a_solid_reaching_into_a_turning_part_is_named(meshes):
    layout, parts = meshes
    # the body with the ball the inner ring swings in left uncut: it holds the inner ring and
    # the end of the reflector part's shaft
    body = shapes.body_shape(layout)
    kept = tuple(c for c in body.cuts if c != shapes.Sphere(layout.swing_radius_mm + 0.2))
    filled = to_manifold(shapes.Difference(body.base, kept), COARSE)
    volume, mesh_volume = filled.volume(), parts.body.volume()
    problems = mesh_disagreement("body", volume, filled, parts)
    assert [p.split(" by ")[0] for p in problems] == [
        f"body: the STEP solid's volume {volume:.1f} mm³ differs from the mesh's "
        f"{mesh_volume:.1f} mm³",
        "body: the STEP solid overlaps the reflector",
        "body: the STEP solid overlaps the inner ring",
    ]
    for line in problems[1:]:
        assert float(line.split(" by ")[1].split()[0]) > OVERLAP_LIMIT_MM3


def test_a_solid_without_a_hole_is_named(meshes):
    layout, parts = meshes
    hole = next(c for c in shapes.body_shape(layout).cuts if isinstance(c, shapes.Cylinder))
    plugged = parts.body + to_manifold(hole, COARSE)  # a tendon hole filled: 0.3 % of the body
    assert mesh_disagreement("body", parts.body.volume(), plugged, parts) == [
        "body: the STEP solid has genus 4, the mesh 5 (a hole too many or missing)"
    ]


def test_a_triangulation_that_is_not_closed_is_named(meshes):
    _, parts = meshes
    problems = mesh_disagreement("reflector", parts.reflector.volume(), mf.Manifold(), parts)
    assert problems == ["reflector: the STEP solid's triangulation is not a closed solid"]
