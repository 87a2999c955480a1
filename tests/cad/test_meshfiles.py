"""STL and 3MF files: what is written reads back as the same named meshes in millimetres."""

import zipfile

import numpy as np
import pytest
import trimesh

from reflector_opt.cad.meshfiles import write_3mf, write_stl
from reflector_opt.util.errors import InputError


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
        np.testing.assert_allclose(back.vertices, mesh.vertices, atol=1e-9)
        assert back.volume == pytest.approx(mesh.volume, rel=1e-9)
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

    monkeypatch.setattr(trimesh.Scene, "export", broken)
    with pytest.raises(InputError, match="No space left"):
        write_3mf(path, objects)
    assert path.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["parts.3mf"]
