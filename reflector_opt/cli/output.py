"""The closing lines of every subcommand: the files it wrote and the command's wall time."""

from __future__ import annotations

import time

__all__ = ["cad_files", "written_lines"]

#: The file entries of a CAD export report, in the order they are listed.
_CAD_KEYS = ("stl", "3mf", "png", "section_png")


def written_lines(paths, started):
    """Closing lines: how many files in what wall time, then each path on its own line.

    Parameters
    ----------
    paths : iterable of str or pathlib.Path
        The files the command wrote, in the order to list them (repeats listed once).
    started : float
        ``time.perf_counter()`` when the command started; the time shown is the wall time of
        the whole command since then, s.

    Returns
    -------
    str
    """
    paths = list(dict.fromkeys(str(path) for path in paths))  # each once, in order
    seconds = time.perf_counter() - started
    if not paths:
        return f"nothing written ({seconds:.1f} s)"
    head = f"wrote {len(paths)} file{'s' if len(paths) > 1 else ''} in {seconds:.1f} s:"
    return "\n".join([head, *(f"  {path}" for path in paths)])


def cad_files(report):
    """The files of a :func:`~reflector_opt.cad.export_parts` report: parts, pictures, report.

    Parameters
    ----------
    report : dict or None
        The export's report (None when nothing was exported).

    Returns
    -------
    list of str
    """
    if report is None:
        return []
    files = [entry[key] for entry in report["files"].values() for key in _CAD_KEYS if key in entry]
    return [*files, report["report"]]
