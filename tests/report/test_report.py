"""The design report: every section, no broken link, embedded images, plain constraint names,
the CAD outcome, the print notes, the command."""

import base64
import copy
import re
import shutil
from dataclasses import replace
from html.parser import HTMLParser
from pathlib import Path

import pytest

from reflector_opt import default_design
from reflector_opt.cli import main
from reflector_opt.design import Reflector, Workspace
from reflector_opt.report._conditions import in_use_block
from reflector_opt.report._in_use import in_use_lines
from reflector_opt.report._outputs import CadOutcome, write_design_outputs
from reflector_opt.report._render import anchor, data_uri, render_markdown
from reflector_opt.report._report import CONSTRAINT_NAMES, SECTIONS, report_blocks

MD_IMAGE = re.compile(r"!\[[^\]]*\]\(([^)]+)\)")
HTML_IMAGE = re.compile(r'<img src="([^"]+)"')
MD_LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)]+)\)")


class _References(HTMLParser):
    """Every href and src of a page, and every id."""

    def __init__(self):
        super().__init__()
        self.references, self.ids = [], set()

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        self.references += [attrs[k] for k in ("href", "src") if k in attrs]
        if "id" in attrs:
            self.ids.add(attrs["id"])


def broken_links(page, folder):
    """The references of an HTML page that resolve to nothing.

    A reference resolves if it is a data URI whose base64 payload decodes, an ``#anchor``
    that some element of the page has as its id, or a file relative to ``folder``.
    """
    parser = _References()
    parser.feed(page)
    broken = []
    for ref in parser.references:
        if ref.startswith("data:"):
            header, _, payload = ref.partition(",")
            ok = header.endswith(";base64") and len(base64.b64decode(payload, validate=True)) > 0
        elif ref.startswith("#"):
            ok = ref[1:] in parser.ids
        else:
            ok = (folder / ref).is_file()
        if not ok:
            broken.append(ref)
    return parser.references, broken


def _coarse(design):
    """The design on a 1° grid, so the report's simulations run in seconds."""
    return design.replace(workspace=Workspace(step_deg=1.0))


@pytest.fixture(scope="module")
def thin_report(design, tmp_path_factory):
    """The default design with its sphere's earlier centre, 1.5 mm below O: its reflecting
    shell, 0.751 mm, is too thin to print."""
    out = tmp_path_factory.mktemp("thin")
    written, cad = write_design_outputs(_centred(design, -1.5), out)
    return out, written, cad


@pytest.fixture(scope="module")
def printable_report(design, tmp_path_factory):
    """Variant A of docs/cad.md: the sphere's centre at z = −1.2 mm passes every check."""
    out = tmp_path_factory.mktemp("printable")
    written, cad = write_design_outputs(_centred(design, -1.2), out)
    return out, written, cad


def _centred(design, z_mm):
    reflector = design.reflector
    return _coarse(design).replace(
        reflector=Reflector(
            radius_mm=reflector.radius_mm,
            centre_mm=(0.0, 0.0, z_mm),
            inner_radius_mm=reflector.inner_radius_mm,
            reflectance=reflector.reflectance,
        )
    )


def _images(out):
    md = (out / "report.md").read_text(encoding="utf-8")
    html = (out / "report.html").read_text(encoding="utf-8")
    return md, html, MD_IMAGE.findall(md), HTML_IMAGE.findall(html)


@pytest.mark.parametrize("which", ["thin_report", "printable_report"])
def test_every_section_and_image_link_resolves(which, request):
    out, written, _ = request.getfixturevalue(which)
    md, html, md_images, html_images = _images(out)
    for section in SECTIONS:
        assert f"\n## {section}\n" in md
        assert f'<h2 id="{anchor(section)}">{section}</h2>' in html
    assert len(md_images) == len(html_images) and len(md_images) >= 10
    for name, src in zip(md_images, html_images, strict=True):
        assert (out / name).is_file() and (out / name).stat().st_size > 1000
        # the page carries the very PNG the Markdown links
        assert src == data_uri((out / name).read_bytes())
    assert set(written[2:]) <= {out / n for n in md_images}
    assert "Segment (Table I)" in md and "RMS paper (°)" in md and "| 2.45 |" in md


@pytest.mark.parametrize("which", ["thin_report", "printable_report"])
def test_html_has_no_broken_link_and_opens_alone(which, request, tmp_path):
    out, _, cad = request.getfixturevalue(which)
    page = (out / "report.html").read_text(encoding="utf-8")
    references, broken = broken_links(page, out)
    assert broken == []
    files = [r for r in references if not r.startswith(("data:", "#"))]
    anchors = [r for r in references if r.startswith("#")]
    assert anchors == [f"#{anchor(s)}" for s in SECTIONS]  # the contents line
    if cad.error is None:  # the part files and the CAD report are linked, nothing else
        assert sorted(files) == [
            "body.3mf",
            "body.stl",
            "cad_report.json",
            "reflector.3mf",
            "reflector.stl",
        ]
    else:
        assert files == []
    # alone in another folder, only the part links can break: every image is inside
    shutil.copy(out / "report.html", tmp_path / "report.html")
    _, broken = broken_links((tmp_path / "report.html").read_text(encoding="utf-8"), tmp_path)
    assert broken == files
    md = (out / "report.md").read_text(encoding="utf-8")
    assert sorted(MD_LINK.findall(md)) == sorted(anchors + files)  # the same links


def test_broken_links_are_found(tmp_path):
    (tmp_path / "here.stl").write_bytes(b"solid")
    page = (
        '<h2 id="a">A</h2><a href="#a">ok</a><a href="#b">no anchor</a>'
        '<a href="here.stl">ok</a><a href="gone.stl">missing</a>'
        f'<img src="{data_uri(b"png")}"><img src="data:image/png;base64,@@">'
    )
    with pytest.raises(ValueError):  # an undecodable data URI is no image at all
        broken_links(page, tmp_path)
    page = page.replace('<img src="data:image/png;base64,@@">', '<img src="f.png">')
    _, broken = broken_links(page, tmp_path)
    assert broken == ["#b", "gone.stl", "f.png"]


def test_constraints_have_plain_names_and_zero_margins_are_flagged(thin_report):
    out, _, _ = thin_report
    md = (out / "report.md").read_text(encoding="utf-8")
    table = md.split("## Constraints")[1].split("## Sensor windows")[0]
    rows = [line.split(" | ") for line in table.splitlines() if line.startswith("| ")][2:]
    assert len(rows) == len(CONSTRAINT_NAMES) - 1  # every one but the printed walls
    for row in rows:
        assert row[0].lstrip("| ") == CONSTRAINT_NAMES[row[-1].strip("`| ")]
        assert row[4] in {"mm", "–", "σ_V"}
    by_key = {row[-1].strip("`| "): row for row in rows}
    # the default design's sensors sit at 10 mm with 1 mm of backing: 11 mm, the unit's radius
    assert by_key["sensor_envelope_mm"][1:4] == ["11.0000", "≤ 11", "0.0000"]
    assert by_key["sensor_envelope_mm"][5] == "**met, zero slack**"
    # the inner radius 7.5 mm less half the 14 mm bearing OD: 0.5 mm, the required clearance
    assert by_key["bearing_clearance_mm"][5] == "**met, zero slack**"
    assert by_key["wall_mm"][5] == "met" and by_key["fold_fraction"][3] == "– (must be 0)"
    assert "**At the limit, with zero slack:** sensor and its backing" in table


def test_print_and_material_section(thin_report, design):
    out, _, _ = thin_report
    md = (out / "report.md").read_text(encoding="utf-8")
    section = md.split("## Print and material")[1]
    assert "| mirror-like (specular) share f of ρ; the rest Lambertian | 0.050 |" in section
    assert "the `white-sla-resin` surface" in section
    for topic in ("**Material.**", "**Orientation and supports.**", "**Resin and post-cure.**"):
        assert topic in section
    matte = design.replace(reflector=replace(design.reflector, specular_fraction=0.0))
    blocks, _ = report_blocks(_coarse(matte), step_deg=3.0)
    assert "the `matte` surface" in render_markdown(blocks)


def test_sections_through_each_sensor(thin_report):
    out, _, _ = thin_report
    md, _, images, _ = _images(out)
    assert images.count("section_1.png") == 1 and images.count("section_2.png") == 1
    assert "S2: section through its own plane, beam and window" in md


def test_unprintable_design_is_reported_not_written(thin_report):
    out, _, cad = thin_report
    assert cad.report is None and "reflecting shell is 0.751 mm thick" in cad.error
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


def test_step_files_are_linked_when_written(design, printable_report, tmp_path):
    _, _, cad = printable_report
    report = copy.deepcopy(cad.report)
    step = tmp_path / "reflector.step"
    step.write_bytes(b"ISO-10303-21;" * 100)
    report["files"]["reflector"].update(step=str(step), step_bytes=step.stat().st_size)
    blocks, _ = report_blocks(_centred(design, -1.2), cad=CadOutcome(report=report), step_deg=3.0)
    md = render_markdown(blocks)
    assert "[reflector.step](reflector.step) (STEP, 1 kB)" in md
    assert "[body.stl](body.stl) (STL," in md and "[cad_report.json](cad_report.json)" in md


def test_the_report_opens_with_the_figures_in_use_and_carries_the_budget(thin_report, design):
    """No conditions given: the default ones, named, their figures first (before the contents
    line) and the budget's table in the "In use" section; the same figures as in_use_block."""
    out, _, _ = thin_report
    md = (out / "report.md").read_text(encoding="utf-8")
    head = md.split("Contents: ")[0]
    block = in_use_block(_centred(design, -1.5))
    expected = in_use_lines(block)[0].strip()
    assert f"\n{expected[0].upper()}{expected[1:]}.\n" in head
    assert f"worst case {block.worst_case_deg:.4f}°" in head and "Quote the worst case" in head
    assert "No operating conditions given" not in md
    assert "Error budget in use: ±2 K from calibration" in md.split("## In use")[1]
