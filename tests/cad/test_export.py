"""Printable CAD export (cad.export): the files written and read back, a failed write or check
leaving nothing, and the ``export`` command."""

import json
import zipfile

import pytest
import trimesh

from reflector_opt.cad import export_parts
from reflector_opt.cli import main
from reflector_opt.design import Mechanics, Reflector, default_design
from reflector_opt.util._errors import InputError
from tests.cad.designs import COARSE, DESIGN_A

# --- files ----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    out = tmp_path_factory.mktemp("cad")
    report = export_parts(
        DESIGN_A,
        out,
        parts=("reflector", "body", "assembly"),
        tolerance_mm=COARSE,
        pose_deg=(15.0, -10.0),
    )
    return out, report


def test_export_writes_every_file(exported):
    out, report = exported
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(
        [
            "reflector.stl",
            "reflector.3mf",
            "reflector.png",
            "body.stl",
            "body.3mf",
            "body.png",
            "assembly.3mf",
            "assembly.png",
            "assembly_section.png",
            "cad_report.json",
        ]
    )
    for entry in report["files"].values():
        for key in ("stl", "3mf", "png"):
            if key in entry:
                assert entry[f"{key}_bytes"] == (out / entry[key].split("/")[-1]).stat().st_size > 0
    refl = report["files"]["reflector"]
    assert refl["stl_bytes"] == 84 + 50 * refl["triangles"]  # binary STL
    assert report["ray_check"]["passed"] and report["collision"]["collision_free"]
    assert report["assembly"]["intersection_mm3"] == 0.0 and report["assembly"]["clearance_mm"] > 0
    assert all(p["ok"] for p in report["printability"].values())


@pytest.mark.parametrize("part", ["reflector", "body"])
def test_stl_and_3mf_read_back_with_the_same_volume(exported, part):
    out, report = exported
    volume = report["printability"][part]["volume_mm3"]
    stl = trimesh.load(out / f"{part}.stl")
    three = trimesh.load(out / f"{part}.3mf", force="mesh")
    for mesh in (stl, three):
        assert mesh.is_watertight
        assert mesh.volume == pytest.approx(volume, rel=1e-5)
    with zipfile.ZipFile(out / f"{part}.3mf") as z:
        assert 'unit="millimeter"' in z.read("3D/3dmodel.model").decode()


def test_assembly_3mf_holds_every_solid(exported):
    out, _ = exported
    scene = trimesh.load(out / "assembly.3mf")
    assert len(scene.geometry) == 5


def test_failed_write_leaves_no_file(tmp_path, monkeypatch):
    import reflector_opt.cad._meshfiles as meshfiles

    def broken(mesh):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(meshfiles, "export_stl", broken)
    with pytest.raises(InputError, match="No space left"):
        export_parts(DESIGN_A, tmp_path, parts=("reflector",), tolerance_mm=COARSE, preview=False)
    assert list(tmp_path.iterdir()) == []


def test_failed_check_leaves_no_picture(tmp_path, monkeypatch):
    """The pictures, drawn while the parts are checked, are dropped when a check fails."""
    import tempfile

    import reflector_opt.cad._export as export
    from reflector_opt.cad._verification import RayCheck

    def failing(mesh, design, tolerance_mm):
        return RayCheck(98, 0, 2.0 * tolerance_mm, tolerance_mm, tolerance_mm)

    private = tmp_path / "private"
    private.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(private))
    monkeypatch.setattr(export, "verify_distances", failing)
    out = tmp_path / "out"
    with pytest.raises(InputError, match="departs from the Eq 3 sphere"):
        export_parts(DESIGN_A, out, parts=("reflector", "assembly"), tolerance_mm=COARSE)
    assert not out.exists()
    assert list(private.iterdir()) == []


def test_default_tolerance_export(tmp_path):
    report = export_parts(DESIGN_A, tmp_path, parts=("reflector",), preview=False)
    assert report["tolerance_mm"] == 0.01
    assert report["printability"]["reflector"]["ok"]
    assert report["ray_check"]["passed"] and report["ray_check"]["max_error_mm"] <= 0.01
    mesh = trimesh.load(tmp_path / "reflector.stl")
    assert mesh.volume == pytest.approx(report["printability"]["reflector"]["volume_mm3"], rel=1e-5)


# --- command line ---------------------------------------------------------------------------


@pytest.fixture
def design_a_json(tmp_path):
    path = tmp_path / "a.json"
    DESIGN_A.save(path)
    return path


def test_cli_export(design_a_json, tmp_path, capsys):
    out = tmp_path / "out"
    code = main(
        [
            "export",
            str(design_a_json),
            "-o",
            str(out),
            "--part",
            "reflector",
            "--chord-tolerance",
            "0.05",
            "--no-preview",
        ]
    )
    assert code == 0
    assert sorted(p.name for p in out.iterdir()) == [
        "cad_report.json",
        "manifest.json",
        "reflector.3mf",
        "reflector.stl",
    ]
    text = capsys.readouterr().out
    assert f"  {out / 'reflector.stl'}\n" in text and f"  {out / 'cad_report.json'}\n" in text
    assert "reflector:" in text and "Eq 3 ray check" in text


def _assert_bad(args, capsys, out, fragment):
    assert main([*args, "--quiet"]) == 2  # no progress lines: stderr is the error alone
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and fragment in err, err
    assert not out.exists() or list(out.iterdir()) == []


@pytest.mark.slow
def test_cli_exports_the_built_in_default_design(tmp_path, capsys):
    """The design every improvement is measured against passes every check ``export`` makes
    at the default chord tolerance: closed meshes, walls (its reflecting shell, the thinnest,
    at least the 0.8 mm wall, designed and on the mesh), clearance proved at every pose and
    the Eq 3 ray check (the same unit with its earlier centre fails: the next test)."""
    path = tmp_path / "default.json"
    default_design().save(path)
    out = tmp_path / "out"
    assert main(["export", str(path), "-o", str(out), "--no-preview", "--json", "-q"]) == 0
    report = json.loads(capsys.readouterr().out)
    wall = default_design().mechanics.min_wall_mm
    for part in report["printability"].values():
        assert part["ok"] and part["watertight"] and part["inside_envelope"], part["problems"]
        assert part["thinnest_wall_mm"] >= wall
    reflector = report["printability"]["reflector"]
    assert reflector["thinnest_wall"] == "reflecting shell"
    assert reflector["shell_mesh_mm"] >= wall - 2 * report["tolerance_mm"]
    collision = report["collision"]
    assert collision["collision_free"] and collision["unproved_cells"] == 0
    assert report["ray_check"]["passed"] and report["ray_check"]["missed"] == 0
    assert (out / "reflector.stl").stat().st_size > 0 and (out / "body.3mf").stat().st_size > 0


def test_cli_thin_shell(tmp_path, capsys):
    # The default unit with its sphere's earlier centre, 1.5 mm below O: a 0.751 mm shell.
    path = tmp_path / "thin.json"
    default_design().replace(reflector=Reflector(centre_mm=(0.0, 0.0, -1.5))).save(path)
    out = tmp_path / "out"
    _assert_bad(
        ["export", str(path), "-o", str(out), "--chord-tolerance", "0.05"],
        capsys,
        out,
        "reflecting shell",
    )


def test_cli_colliding_parts(tmp_path, capsys):
    # Springs of 4 mm instead of 6: the flange, tilted 21° at a corner of the workspace,
    # would come down onto the body.
    short = DESIGN_A.replace(mechanics=Mechanics(link_length_mm=16.0))
    path = tmp_path / "short.json"
    short.save(path)
    out = tmp_path / "out"
    _assert_bad(
        ["export", str(path), "-o", str(out), "--chord-tolerance", "0.05"],
        capsys,
        out,
        "flange tilted",
    )


def test_cli_unwritable_output(design_a_json, tmp_path, capsys):
    blocker = tmp_path / "blocker"
    blocker.write_text("a file, not a folder")
    out = blocker / "sub"
    code = main(
        [
            "export",
            str(design_a_json),
            "-o",
            str(out),
            "--part",
            "reflector",
            "--chord-tolerance",
            "0.05",
        ]
    )
    assert code == 2
    assert "cannot write" in capsys.readouterr().err
    assert blocker.read_text() == "a file, not a folder"


@pytest.mark.parametrize("tolerance", ["0", "0.2", "nan"])
def test_cli_bad_tolerance(design_a_json, tmp_path, capsys, tolerance):
    out = tmp_path / "out"
    _assert_bad(
        ["export", str(design_a_json), "-o", str(out), "--chord-tolerance", tolerance],
        capsys,
        out,
        "tolerance",
    )


def test_cli_missing_design(tmp_path, capsys):
    out = tmp_path / "out"
    _assert_bad(["export", str(tmp_path / "nope.json"), "-o", str(out)], capsys, out, "cannot read")


def test_cad_builds_from_the_layout_the_optimiser_judges():
    """The optimiser judges walls with the same layout the CAD builds from (DESIGN.md §5)."""
    import reflector_opt.cad as cad
    import reflector_opt.design._layout as layout
    import reflector_opt.design._parts as parts

    assert cad.plan_layout is layout.plan_layout and cad.Layout is layout.Layout
    assert cad.CadParameters is parts.CadParameters
