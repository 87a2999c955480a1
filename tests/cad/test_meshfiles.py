"""STL and 3MF files: what is written reads back as the same named meshes in millimetres,
byte for byte the same for the same meshes, with UUIDs that name the content, and 3MF that
lib3mf reads without a warning."""

import zipfile

import lib3mf
import numpy as np
import pytest
import trimesh
from lxml import etree

import reflector_opt.cad._meshfiles as meshfiles
from reflector_opt.cad import PARTS, export_parts
from reflector_opt.cad._meshfiles import write_3mf, write_stl
from reflector_opt.util._errors import InputError
from tests.cad.designs import DESIGN_A

PRODUCTION_NAMESPACE = "http://schemas.microsoft.com/3dmanufacturing/production/2015/06"


@pytest.fixture
def objects():
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=9.0)
    box = trimesh.creation.box((20.0, 12.0, 4.0))
    box.apply_translation((0.0, 0.0, -15.0))
    # names a hand-written XML would have had to escape
    return {"reflector": sphere, 'body & <ring> "A"': box}


def test_3mf_reads_back_with_names_units_and_meshes(tmp_path, objects):
    path = tmp_path / "parts.3mf"
    write_3mf(path, objects)
    assert [p.name for p in tmp_path.iterdir()] == ["parts.3mf"]  # no temporary file left
    with zipfile.ZipFile(path) as z:
        assert 'unit="millimeter"' in z.read("3D/3dmodel.model").decode()
    scene = trimesh.load(path, file_type="3mf")
    assert scene.units in ("millimeter", "millimeters", "mm")
    assert sorted(scene.geometry) == sorted(objects)
    for name, mesh in objects.items():
        back = scene.geometry[name]
        assert (len(back.vertices), len(back.faces)) == (len(mesh.vertices), len(mesh.faces))
        assert np.array_equal(back.faces, mesh.faces)
        # single precision, as in the STL: a millionth of the part's size
        np.testing.assert_allclose(back.vertices, mesh.vertices, atol=2e-6)
        assert back.volume == pytest.approx(mesh.volume, rel=1e-6)
        transform, geometry = scene.graph[name]
        assert geometry == name and np.array_equal(transform, np.eye(4))


def test_3mf_leaves_the_meshes_as_they_were(tmp_path, objects):
    before = {k: (m.vertices.copy(), m.units) for k, m in objects.items()}
    write_3mf(tmp_path / "parts.3mf", objects)
    for name, mesh in objects.items():
        assert np.array_equal(mesh.vertices, before[name][0]) and mesh.units == before[name][1]


def test_stl_reads_back(tmp_path, objects):
    path = tmp_path / "reflector.stl"
    write_stl(path, objects["reflector"])
    back = trimesh.load(path)
    assert len(back.faces) == len(objects["reflector"].faces)
    assert back.volume == pytest.approx(objects["reflector"].volume, rel=1e-6)


def test_a_failed_3mf_write_keeps_the_old_file(tmp_path, objects, monkeypatch):
    path = tmp_path / "parts.3mf"
    path.write_bytes(b"old")

    def broken(self, *args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(meshfiles, "threemf_bytes", broken)
    with pytest.raises(InputError, match="No space left"):
        write_3mf(path, objects)
    assert path.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["parts.3mf"]


def test_the_same_meshes_give_the_same_bytes(tmp_path, objects):
    for folder in ("a", "b"):
        (tmp_path / folder).mkdir()
        write_stl(tmp_path / folder / "reflector.stl", objects["reflector"])
        write_3mf(tmp_path / folder / "parts.3mf", objects)
    for name in ("reflector.stl", "parts.3mf"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()


def test_an_export_twice_gives_the_same_files(tmp_path):
    for folder in ("a", "b"):
        export_parts(DESIGN_A, tmp_path / folder, parts=PARTS, tolerance_mm=0.05, preview=False)
    names = sorted(p.name for p in (tmp_path / "a").iterdir() if p.suffix in (".stl", ".3mf"))
    assert names == ["assembly.3mf", "body.3mf", "body.stl", "reflector.3mf", "reflector.stl"]
    for name in names:
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes(), name


def _model(path):
    with zipfile.ZipFile(path) as z:
        return etree.fromstring(z.read("3D/3dmodel.model"))


def test_3mf_uuids_name_the_content(tmp_path, objects):
    write_3mf(tmp_path / "a.3mf", objects)
    moved = dict(
        objects, reflector=objects["reflector"].copy().apply_translation((0.0, 0.0, 0.001))
    )
    write_3mf(tmp_path / "b.3mf", moved)
    uuid = f"{{{PRODUCTION_NAMESPACE}}}UUID"
    a, b = (
        [e.get(uuid) for e in _model(tmp_path / f"{n}.3mf").iter() if e.get(uuid)] for n in "ab"
    )
    # the build, two objects and two items, all different; the moved mesh changes its object,
    # its item and the build, the other object and item keep theirs
    assert len(set(a)) == len(a) == 5
    assert sum(x != y for x, y in zip(a, b, strict=True)) == 3


def test_3mf_build_objects_and_items_carry_their_uuid(tmp_path, objects):
    write_3mf(tmp_path / "parts.3mf", objects)
    model = _model(tmp_path / "parts.3mf")
    tags = [e.tag.split("}")[1] for e in model.iter() if e.get(f"{{{PRODUCTION_NAMESPACE}}}UUID")]
    assert sorted(tags) == ["build", "item", "item", "object", "object"]
    items = [e for e in model.iter() if e.tag.endswith("}item")]
    assert [e.get("partnumber") for e in items] == list(objects)


def test_lib3mf_reads_the_3mf_without_warnings(tmp_path, objects):
    write_3mf(tmp_path / "parts.3mf", objects)
    model = lib3mf.get_wrapper().CreateModel()
    reader = model.QueryReader("3mf")
    reader.ReadFromFile(str(tmp_path / "parts.3mf"))
    assert [reader.GetWarning(i) for i in range(reader.GetWarningCount())] == []
    names = []
    found = model.GetObjects()
    while found.MoveNext():
        names.append(found.GetCurrentObject().GetName())
    assert names == list(objects)
