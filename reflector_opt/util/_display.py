"""Short displays of result objects: a one-screen ``repr`` and an HTML table for notebooks.

An object lists its key figures as (label, value) rows; :func:`text_summary` makes the
``__repr__`` text of them and :func:`html_summary` the ``_repr_html_`` table (every piece of
text escaped with :func:`html.escape`). A result class inherits both from :class:`Summarised`
and lists its rows in one ``_summary`` method.
"""

import html
import math


def fmt(value, digits=3, unit=""):
    """A number with ``digits`` significant digits and its unit; ``n/a`` if missing or NaN.

    Parameters
    ----------
    value : float or None
    digits : int
        Significant digits.
    unit : str
        Appended after a space (``°`` and ``%`` without one).

    Returns
    -------
    str
    """
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    text = f"{float(value):.{digits}g}"
    if not unit:
        return text
    return f"{text}{unit}" if unit in ("°", "%") else f"{text} {unit}"


def vector(values, decimals=3, unit=""):
    """``(x, y, z)`` with fixed decimals and the unit after it."""
    text = "(" + ", ".join(f"{float(v):.{decimals}f}" for v in values) + ")"
    return f"{text} {unit}" if unit else text


def span(low, high, digits=3, unit=""):
    """``low to high unit``; one value if they agree to ``digits``; ``n/a`` if one is missing."""
    if low is None or high is None or math.isnan(low) or math.isnan(high):
        return "n/a"
    if fmt(low, digits) == fmt(high, digits):
        return fmt(low, digits, unit)
    return f"{fmt(low, digits)} to {fmt(high, digits, unit)}"


def more_rows(count, shown, noun):
    """The row that says how many of ``count`` items a summary left out after the first ``shown``.

    Parameters
    ----------
    count : int
        Items there are.
    shown : int
        Items the summary lists.
    noun : str
        What an item is, plural (``"levels"``).

    Returns
    -------
    list of (str, str)
        ``[("…", "N more <noun>")]``, or no row when nothing is left out.
    """
    return [("…", f"{count - shown} more {noun}")] if count > shown else []


def text_summary(title, rows):
    """The ``repr`` text: the title, then one indented ``label: value`` line per row."""
    return "\n".join([title, *(f"  {label}: {value}" for label, value in rows)])


def html_summary(title, rows):
    """An HTML table of the rows under a bold title; all text escaped.

    Parameters
    ----------
    title : str
    rows : list of (str, str)

    Returns
    -------
    str
    """
    body = "".join(
        f'<tr><th style="text-align:left">{html.escape(str(label))}</th>'
        f'<td style="text-align:left">{html.escape(str(value))}</td></tr>'
        for label, value in rows
    )
    return f"<table><caption><b>{html.escape(title)}</b></caption>{body}</table>"


class Summarised:
    """Mixin: a one-screen ``repr`` and a notebook table of an object's key figures.

    A subclass defines ``_summary(self) -> (title, rows)``, rows a list of (label, value)
    strings; a dataclass that inherits it is declared with ``repr=False`` so that the
    dataclass's own ``repr`` does not replace this one.
    """

    __slots__ = ()

    def _summary(self):
        raise NotImplementedError

    def __repr__(self):
        return text_summary(*self._summary())

    def _repr_html_(self):
        return html_summary(*self._summary())


class Printed:
    """Mixin for a command's run: its ``repr`` and notebook display are what the command prints.

    A subclass defines ``text(self) -> str``, the command's summary; a dataclass that inherits
    it is declared with ``repr=False``.
    """

    __slots__ = ()

    def text(self):
        raise NotImplementedError

    def __repr__(self):
        return self.text()

    def _repr_html_(self):
        return f"<pre>{html.escape(self.text())}</pre>"
