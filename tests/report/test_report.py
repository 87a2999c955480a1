"""The design report: every section, resolvable image links, the CAD outcome, the command."""

import re
from pathlib import Path

import pytest

from reflector_opt import default_design
from reflector_opt.cli import main
from reflector_opt.design import Reflector, Workspace
from reflector_opt.report.report import (
    SECTIONS,
    render_html,
    render_markdown,
    report_blocks,
    write_design_outputs,
)

MD_IMAGE = re.compile(r"!\[[^\]]*\]\(([^)]+)\)")
HTML_IMAGE = re.compile(r'<img src="([^"]+)"')


def _coarse(design):
    """The design on a 1° grid, so the report's simulations run in seconds."""
    return design.replace(workspace=Workspace(step_deg=1.0))


@pytest.fixture(scope="module")
def default_report(design, tmp_path_factory):
    out = tmp_path_factory.mktemp("default")
    written, cad = write_design_outputs(_coarse(design), out)
    return out, written, cad


@pytest.fixture(scope="module")
def printable_report(design, tmp_path_factory):
    """Variant A of docs/cad.md: the sphere's centre at z = −1.2 mm passes every check."""
    out = tmp_path_factory.mktemp("printable")
    reflector = design.reflector
    printable = _coarse(design).replace(
        reflector=Reflector(
            radius_mm=reflector.radius_mm,
            centre_mm=(0.0, 0.0, -1.2),
            inner_radius_mm=reflector.inner_radius_mm,
            reflectance=reflector.reflectance,
        )
    )
    written, cad = write_design_outputs(printable, out)
    return out, written, cad


def _images(out):
    md = (out / "report.md").read_text(encoding="utf-8")
    html = (out / "report.html").read_text(encoding="utf-8")
    return md, html, MD_IMAGE.findall(md), HTML_IMAGE.findall(html)


@pytest.mark.parametrize("which", ["default_report", "printable_report"])
def test_every_section_and_image_link_resolves(which, request):
    out, written, _ = request.getfixturevalue(which)
    md, html, md_images, html_images = _images(out)
    for section in SECTIONS:
        assert f"\n## {section}\n" in md
        assert f"<h2>{section}</h2>" in html
    assert md_images == html_images and len(md_images) >= 10
    for name in md_images:
        assert (out / name).is_file() and (out / name).stat().st_size > 1000
    assert set(written[2:]) <= {out / n for n in md_images}
    assert "Segment (Table I)" in md and "RMS paper (°)" in md and "| 2.45 |" in md


def test_unprintable_design_is_reported_not_written(default_report):
    out, _, cad = default_report
    assert cad.report is None and "reflecting shell is 0.741 mm thick" in cad.error
    md = (out / "report.md").read_text(encoding="utf-8")
    assert "**The design cannot be printed as it stands**" in md
    assert cad.error in md
    assert not list(out.glob("*.stl"))
    html = (out / "report.html").read_text(encoding="utf-8")
    assert "<strong>The design cannot be printed as it stands</strong>" in html


def test_printable_design_links_its_parts(printable_report):
    out, _, cad = printable_report
    assert cad.error is None
    assert (out / "reflector.stl").is_file() and (out / "body.stl").is_file()
    md, _, images, _ = _images(out)
    assert "reflector.png" in images and "body.png" in images
    assert "| reflector | yes | yes | yes |" in md


def test_html_escapes_text_and_renders_the_same_blocks():
    blocks = [
        ("h1", "a < b"),
        ("p", "**bold** & plain"),
        ("table", ("x", "y|z"), [("1", "<2>")]),
        ("code", "if a < b:"),
        ("img", "f.png", 'say "hi"'),
    ]
    html = render_html(blocks)
    assert "<h1>a &lt; b</h1>" in html
    assert "<p><strong>bold</strong> &amp; plain</p>" in html
    assert "<td>&lt;2&gt;</td>" in html and "<pre>if a &lt; b:</pre>" in html
    assert '<img src="f.png" alt="say &quot;hi&quot;">' in html
    md = render_markdown(blocks)
    assert "| x | y\\|z |" in md and '![say "hi"](f.png)' in md


def test_report_command(design, tmp_path, capsys):
    path = tmp_path / "design.json"
    _coarse(design).save(path)
    out = tmp_path / "rep"
    assert main(["report", str(path), "--out", str(out), "--no-cad", "--quiet"]) == 0
    text = capsys.readouterr().out
    listed = text.splitlines()[-len(list(out.iterdir())) :]
    assert sorted(listed) == sorted(f"  {p}" for p in out.iterdir())  # every file, last
    assert listed[:2] == [f"  {out / 'report.md'}", f"  {out / 'report.html'}"]
    md = (out / "report.md").read_text(encoding="utf-8")
    assert "The CAD export was not run for this report." in md


def test_report_command_bad_input(tmp_path, capsys):
    assert main(["report", str(tmp_path / "missing.json"), "--quiet"]) == 2
    assert "missing.json" in capsys.readouterr().err
    blocker = tmp_path / "file"
    blocker.write_text("x", encoding="utf-8")
    path = tmp_path / "design.json"
    default_design().save(path)
    assert main(["report", str(path), "--out", str(blocker), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "exists and is not a folder" in err
    assert blocker.read_text(encoding="utf-8") == "x"
    assert not list(Path(tmp_path).glob("*.png"))


def test_constraints_that_do_not_apply_are_said_so(design):
    # a usable range of 0.15 mm leaves no room for the optimiser's 0.1 mm margins at both ends
    model = design.models[0].with_(range_mm=(0.5, 0.65))
    odd = _coarse(design).with_sensor_model(model)
    blocks, figures = report_blocks(odd, step_deg=2.0)
    text = render_markdown(blocks)
    assert "The optimiser's constraints do not apply: distance window" in text
    assert "## Resolution" in text and "resolution_maps.png" in figures
