"""The report's blocks rendered as Markdown and as one HTML page, from the Jinja templates in
``reflector_opt/report/templates`` (shipped with the package).

A block is ``("h1"|"h2"|"h3"|"p"|"code", text)``, ``("table", header, rows)`` or
``("img", file name, caption)`` (:func:`reflector_opt.report._report.report_blocks`), or
``("html", fragment, Markdown text)``: a piece of page made by the package's own templates
(the 3D view, :mod:`reflector_opt.report._view3d`), put in the HTML as it is and replaced by
the text in Markdown. Text may
carry the report's inline Markdown: ``[text](href)`` links, ``**bold**`` and ```code```. The
HTML template autoescapes; text reaches it through the ``inline`` filter, which escapes it
first and only then turns that Markdown into tags.
"""

import base64
import functools
import html
import re

from jinja2 import Environment, PackageLoader, StrictUndefined, select_autoescape
from markupsafe import Markup

#: The inline Markdown the report's text uses: links (bold and code are split on their marks).
_LINK = re.compile(r"\[([^\]]+)\]\(([^)\s]+)\)")


def anchor(heading):
    """The fragment id of a heading: lower case, spaces as hyphens, punctuation dropped.

    The same rule as GitHub's Markdown, so ``#anchor`` links work in both renderings.
    """
    kept = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return kept.replace(" ", "-")


def data_uri(png):
    """A PNG's bytes as a ``data:image/png;base64,…`` URI, for an image inside the page."""
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def _escape_text(text):
    """HTML-escaped text (quotes too), marked safe so that autoescaping leaves it as it is."""
    return Markup(html.escape(str(text)))


def _inline_html(text):
    """Escape, then turn the report's ``[text](href)``, ``**bold**`` and ```code``` into HTML."""
    escaped = html.escape(str(text))
    escaped = _LINK.sub(lambda m: f'<a href="{m.group(2)}">{m.group(1)}</a>', escaped)
    parts = escaped.split("**")
    escaped = "".join(f"<strong>{p}</strong>" if i % 2 else p for i, p in enumerate(parts))
    parts = escaped.split("`")
    return Markup("".join(f"<code>{p}</code>" if i % 2 else p for i, p in enumerate(parts)))


def _md_cell(text):
    return str(text).replace("|", "\\|")


@functools.cache
def _environment():
    """The templates' environment: HTML autoescaped, Markdown as written; blocks trimmed."""
    env = Environment(
        loader=PackageLoader("reflector_opt.report", "templates"),
        autoescape=select_autoescape(enabled_extensions=("html.j2",), default=False),
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        undefined=StrictUndefined,
    )
    env.filters.update(
        anchor=anchor,
        data_uri=data_uri,
        escape_text=_escape_text,
        inline=_inline_html,
        md_cell=_md_cell,
    )
    return env


def render_template(name, **context):
    """Render one of the package's templates (``report/templates/NAME``) with the report's
    filters; an ``.html.j2`` template autoescapes.

    Parameters
    ----------
    name : str
        The template's file name.
    **context
        The template's variables.

    Returns
    -------
    str
    """
    return _environment().get_template(name).render(**context)


def render_markdown(blocks):
    """Markdown text of report blocks (template ``report.md.j2``).

    Parameters
    ----------
    blocks : list of tuple
        The report's blocks (see the module's docstring).

    Returns
    -------
    str
        Each block followed by a blank line, the last by a single newline.
    """
    return render_template("report.md.j2", blocks=blocks)


def render_html(blocks, title="Reflector design report", images=None):
    """A standalone HTML page of report blocks (template ``report.html.j2``).

    Parameters
    ----------
    blocks : list of tuple
        The report's blocks (see the module's docstring).
    title : str, optional
    images : mapping of str to bytes, optional
        PNG bytes by image file name: those images are embedded as data URIs, so the page
        needs no file beside it; others are linked by name.

    Returns
    -------
    str
    """
    return render_template("report.html.j2", blocks=blocks, title=title, images=images or {})
