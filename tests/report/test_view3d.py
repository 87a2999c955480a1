"""The 3D view's content: slider grid, the model's distances and beams at each pose (against
hand-computed Eq 1–3 with an independent rotation), the meshes against the model's sphere,
the cut-away, a page with no outside reference, and the report's section in both renderings.
The page in a real browser: tests/report/test_view3d_browser.py."""

import base64
import re

import numpy as np
import pytest
import trimesh
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from reflector_opt.design import Reflector, load_design
from reflector_opt.report._render import render_html, render_markdown
from reflector_opt.report._view3d import (
    VIEW_FILE,
    VIEW_SIMPLIFY_MM,
    design_view,
    slider_values,
    view_blocks,
    view_scene,
    write_view,
)
from tests.processes import ROOT

SAMPLE = ROOT / "examples" / "data" / "design.json"


@pytest.fixture(scope="module")
def sample():
    design = load_design(SAMPLE)
    return design, view_scene(design)


def _floats(text, *shape):
    return np.frombuffer(base64.b64decode(text), dtype="<f4").astype(float).reshape(shape)


def _mesh(entry):
    vertices = _floats(entry["vertices"], -1, 3)
    faces = np.frombuffer(base64.b64decode(entry["faces"]), dtype="<u4").reshape(-1, 3)
    return trimesh.Trimesh(vertices, faces, process=False)


def test_slider_values_take_the_ends_and_whole_steps_between():
    assert_allclose(slider_values((-15, 15)), np.arange(-15.0, 16.0))  # 1° steps
    assert_allclose(slider_values((-2.5, 2.5)), [-2.5, -2, -1, 0, 1, 2, 2.5])  # zero held
    assert_allclose(slider_values((-40.0, 35.0)), [-40.0, *range(-35, 35, 5), 35.0])  # 5° steps
    assert_allclose(slider_values((-20.0, 40.0)), np.arange(-20.0, 41.0, 2.0))  # 60° in 2° steps
    assert_allclose(slider_values((3.0, 3.0)), [3.0])


def _hand_eq3(design, pitch_deg, roll_deg):
    """Eq 1–3 by hand: s1 = Rx(α)·Ry(γ)·s0 with scipy's intrinsic X-then-Y rotation."""
    turn = Rotation.from_euler("XY", [roll_deg, pitch_deg], degrees=True).as_matrix()
    s1 = turn @ np.asarray(design.reflector.centre_mm)
    f = np.asarray([s.position_mm for s in design.sensors])
    return np.linalg.norm(f - s1, axis=1) - design.reflector.radius_mm, s1, turn


def test_distances_and_beams_are_eq3_at_every_slider_pose(sample):
    design, scene = sample
    pitch, roll = scene["pitch_deg"], scene["roll_deg"]
    assert pitch == list(np.arange(-15.0, 16.0)) and roll == pitch  # the workspace's ±15°
    assert scene["start"] == [15, 15]  # zero pose
    shape = (len(pitch), len(roll), len(design.sensors))
    distance = _floats(scene["distance_mm"], *shape)
    axial = _floats(scene["axial_mm"], *shape)
    hit = _floats(scene["hit_mm"], *shape, 3)
    nearest = _floats(scene["nearest_mm"], *shape, 3)
    f = np.asarray([s.position_mm for s in design.sensors])
    r_s = design.reflector.radius_mm
    for i, j in [(15, 15), (0, 30), (30, 0), (22, 7)]:
        d, s1, turn = _hand_eq3(design, pitch[i], roll[j])
        assert_allclose(distance[i, j], d, atol=2e-6)
        # the page's rotation Rx·Ry of the model's matrices is the same rotation
        assert_allclose(np.asarray(scene["rx"][j]) @ np.asarray(scene["ry"][i]), turn, atol=1e-12)
        # the dashed Eq 3 segment ends on the sphere, d from the sensor, on the line to s1
        assert_allclose(np.linalg.norm(nearest[i, j] - s1, axis=1), r_s, atol=1e-5)
        assert_allclose(np.linalg.norm(nearest[i, j] - f, axis=1), d, atol=1e-5)
        # the beam runs along each axis and ends on the sphere
        axes = np.asarray(design.axes) / np.linalg.norm(design.axes, axis=1)[:, None]
        assert_allclose(hit[i, j], f + axial[i, j][:, None] * axes, atol=1e-5)
        assert_allclose(np.linalg.norm(hit[i, j] - s1, axis=1), r_s, atol=1e-5)
        assert np.all(axial[i, j] >= d - 1e-6)  # never shorter than the shortest way
    # the sample design at zero pose, by hand from design.json: sensor (9.6717, ±2.5415,
    # −0.3823), centre (1.1182, 0, 1.0903), r_s 8.1060 → √(8.5535² + 2.5415² + 1.4726²) − 8.1060
    assert_allclose(distance[15, 15], [0.9378, 0.9378], atol=1e-3)


def test_meshes_are_the_parts_and_the_reflector_meets_the_model(sample):
    design, scene = sample
    meshes = {entry["name"]: entry for entry in scene["meshes"]}
    assert set(meshes) == {"reflector", "inner_ring", "body", "outer_ring", "sensors"}
    assert {n for n, e in meshes.items() if e["rotating"]} == {"reflector", "inner_ring"}
    # at zero pose the reflector's mesh is Eq 3's distance from each sensor (the export's
    # ray check on the part's mesh, here on the view's simplified mesh)
    reflector = _mesh(meshes["reflector"])
    assert reflector.is_watertight
    f = np.asarray([s.position_mm for s in design.sensors])
    _, gap, _ = trimesh.proximity.closest_point(reflector, f)
    d, _, _ = _hand_eq3(design, 0.0, 0.0)
    assert_allclose(gap, d, atol=VIEW_SIMPLIFY_MM + 0.01)
    # the body is cut away on the sensors' side (their mean direction): none of it is left there
    towards = f[:, :2].mean(axis=0) / np.linalg.norm(f[:, :2].mean(axis=0))
    body = _mesh(meshes["body"])
    assert body.is_watertight and (body.vertices[:, :2] @ towards).max() < 1e-4
    assert (body.vertices[:, :2] @ towards).min() < -10.0  # the far half is there
    total = sum(e["triangles"] for e in scene["meshes"])
    assert 3000 < total < 20000


def test_page_needs_nothing_from_outside(sample, tmp_path):
    design, _ = sample
    path = write_view(design, tmp_path)
    assert path == tmp_path / VIEW_FILE
    page = path.read_text(encoding="utf-8")
    assert page.startswith("<!DOCTYPE html>") and page.count('<div class="view3d">') == 1
    assert not re.search(r"\b(src|href)=|https?:|//cdn|@import|url\(", page)
    data = re.search(r'class="view3d-data">(.*?)</script>', page, re.DOTALL).group(1)
    assert "<" not in data  # the JSON cannot close its script element
    assert 100_000 < path.stat().st_size < 600_000


def test_report_section_in_html_and_markdown(sample):
    design, _ = sample
    blocks = view_blocks(design)
    assert [b[0] for b in blocks] == ["h2", "p", "html"]
    html = render_html([("h1", "t"), *blocks])
    assert html.count("<canvas") == 1 and '<h2 id="3d-view">3D view</h2>' in html
    assert "&lt;canvas" not in html  # the fragment is put in as it is, not escaped
    markdown = render_markdown(blocks)
    assert "<canvas" not in markdown and "open that page in a browser" in markdown
    assert "## 3D view" in markdown


def test_a_design_whose_parts_cannot_be_made_has_the_reason():
    design = load_design(SAMPLE)
    bad = design.replace(reflector=Reflector(9.0, (0.0, 0.0, -1.5), 5.0))
    blocks = view_blocks(bad)
    assert blocks[0] == ("h2", "3D view") and len(blocks) == 2
    assert blocks[1][1].startswith("No 3D view: reflector.inner_radius_mm: 5 mm does not clear")
    with pytest.raises(Exception, match="does not clear the bearing"):
        design_view(bad)


def test_export_writes_the_view_into_its_folder(monkeypatch, tmp_path, capsys):
    """``reflector-opt export`` writes view.html inside its folder swap (listed in the
    manifest, named in --json); the parts' export itself is stubbed, it has its own tests."""
    import json

    import reflector_opt.cad._export as cad_export
    from reflector_opt.cli import main

    def parts_only(design, out_dir, **options):
        (out_dir / "cad_report.json").write_text("{}")
        return {"files": {}, "report": "cad_report.json"}

    monkeypatch.setattr(cad_export, "export_parts", parts_only)
    out = tmp_path / "out"
    assert main(["export", str(SAMPLE), "-o", str(out), "--json", "--quiet"]) == 0
    assert json.loads(capsys.readouterr().out)["view"] == VIEW_FILE
    manifest = json.loads((out / "manifest.json").read_text())
    assert VIEW_FILE in [entry["path"] for entry in manifest["files"]]
    assert (out / VIEW_FILE).read_text(encoding="utf-8").count("<canvas") == 1
    assert main(["export", str(SAMPLE), "-o", str(out), "--no-preview", "--json", "-q"]) == 0
    assert "view" not in json.loads(capsys.readouterr().out) and not (out / VIEW_FILE).exists()
