"""reflector_opt.report._render: the report's blocks as Markdown and as one HTML page."""

import fnmatch
import tomllib
from pathlib import Path

from reflector_opt.report._render import anchor, data_uri, render_html, render_markdown

ROOT = Path(__file__).resolve().parents[2]


def test_an_anchor_is_the_heading_in_lower_case_without_punctuation():
    assert anchor("  Print & material ") == "print--material"
    assert anchor("Sensor choice (NJL5901R-2)") == "sensor-choice-njl5901r-2"


def test_a_data_uri_carries_the_bytes_in_base64():
    assert data_uri(b"png") == "data:image/png;base64,cG5n"  # b"png" -> "cG5n" by hand


def test_an_embedded_image_is_its_data_uri_and_another_is_linked():
    page = render_html([("img", "a.png", "A"), ("img", "b.png", "B")], images={"a.png": b"png"})
    assert '<img src="data:image/png;base64,cG5n" alt="A">' in page
    assert '<img src="b.png" alt="B">' in page


def test_html_escapes_text_and_renders_the_same_blocks():
    blocks = [
        ("h1", "a < b"),
        ("p", "**bold** & plain"),
        ("table", ("x", "y|z"), [("1", "<2>")]),
        ("code", "if a < b:"),
        ("img", "f.png", 'say "hi"'),
    ]
    html = render_html(blocks)
    assert '<h1 id="a--b">a &lt; b</h1>' in html
    assert "<p><strong>bold</strong> &amp; plain</p>" in html
    assert "<td>&lt;2&gt;</td>" in html and "<pre>if a &lt; b:</pre>" in html
    assert '<img src="f.png" alt="say &quot;hi&quot;">' in html
    md = render_markdown(blocks)
    assert "| x | y\\|z |" in md and '![say "hi"](f.png)' in md


def test_templates_escape_every_text_and_keep_the_markdown_as_written():
    script = "<script>alert('x')</script>"
    blocks = [
        ("h2", script),
        ("p", f"see [the parts](parts.md) and `{script}` & **{script}**"),
        ("table", (script,), [(script,)]),
        ("code", script),
        ("img", 'a"b.png', script),
    ]
    page = render_html(blocks, title=script)
    assert "<script>" not in page and "&lt;script&gt;alert(&#x27;x&#x27;)&lt;/script&gt;" in page
    assert '<a href="parts.md">the parts</a>' in page
    assert "<code>&lt;script&gt;" in page and "<strong>&lt;script&gt;" in page
    assert '<img src="a&quot;b.png" alt="&lt;script&gt;' in page
    assert page.startswith("<!DOCTYPE html>\n") and page.endswith("</body>\n</html>\n")
    # Markdown is text: written as given, each block then a blank line, one newline at the end
    md = render_markdown(blocks)
    assert md.startswith(f"## {script}\n\nsee [the parts](parts.md)")
    assert md.endswith(f'```\n{script}\n```\n\n![{script}](a"b.png)\n')


def test_templates_are_package_data():
    # a non-editable install carries only the files pyproject's package-data names
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    globs = tomllib.loads(text)["tool"]["setuptools"]["package-data"]["reflector_opt"]
    templates = sorted((ROOT / "reflector_opt" / "report" / "templates").iterdir())
    assert {t.name for t in templates} == {
        "report.md.j2",
        "report.html.j2",
        "view3d.html.j2",  # the 3D view (report.view3d): its element, page and script
        "view3d_page.html.j2",
        "view3d.js",
    }
    for template in templates:
        relative = template.relative_to(ROOT / "reflector_opt").as_posix()
        assert any(fnmatch.fnmatch(relative, glob) for glob in globs), relative
