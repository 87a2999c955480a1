"""STEP export: exact solids read back as one valid solid per part, matching the meshes.

The tests that build solids need the optional build123d (``pip install '.[step]'``) and skip
without it; the refusal without it is tested either way.
"""

import sys

import manifold3d as mf
import numpy as np
import pytest
import trimesh

from reflector_opt.cad import export_parts, plan_layout
from reflector_opt.cad.step import build_step_parts, step_available
from reflector_opt.cli import main
from reflector_opt.design import Reflector, SensorPlacement, default_design
from reflector_opt.util.errors import InputError

#: Chord tolerance of the meshes compared with the STEP solids, mm.
TOLERANCE = 0.01
#: Chord tolerance of the STEP solids' own triangulation in the comparison, mm.
STEP_TESSELLATION = 0.002

# the printable variant of docs/cad.md: the default design with its centre 1.2 mm below O
DESIGN_A = default_design().replace(
    reflector=Reflector(9.0, (0.0, 0.0, -1.2), 7.5),
    sensors=(
        SensorPlacement("S1", "NJL5901R-2", (10.0, 0.0, 0.0), (-1.0, 0.0, 0.0)),
        SensorPlacement("S2", "NJL5901R-2", (0.0, 10.0, 0.0), (0.0, -1.0, 0.0)),
    ),
)


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
        build_step_parts(plan_layout(DESIGN_A))
