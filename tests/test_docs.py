"""The documentation's relative links point to files that exist."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def test_relative_markdown_links_resolve():
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    links = [
        (page.relative_to(ROOT), target)
        for page in pages
        for target in LINK.findall(page.read_text(encoding="utf-8"))
        if not re.match(r"[a-z][a-z0-9+.-]*:|#", target)
    ]
    assert links  # the pages do link to each other
    broken = [
        (page, target)
        for page, target in links
        if not (ROOT / page).parent.joinpath(target.split("#")[0]).exists()
    ]
    assert broken == []
