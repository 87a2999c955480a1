"""File input and output with errors a user can act on.

Output is atomic: written to a temporary file beside the target, then renamed, so a failure
part-way (a full disk, an exception while serialising) leaves the target as it was and no
truncated file behind. Input of text, JSON and TOML turns every failure into one
:class:`~reflector_opt.util.errors.InputError` naming the file.
"""

from __future__ import annotations

import json
import os
import tempfile
import tomllib
from contextlib import contextmanager
from pathlib import Path

from reflector_opt.util.errors import InputError

__all__ = ["atomic_path", "read_json", "read_text", "read_toml", "write_json", "write_text"]


@contextmanager
def atomic_path(path, suffix=""):
    """Yield a temporary path in the target's folder; rename it onto ``path`` on success.

    Parameters
    ----------
    path : str or pathlib.Path
        Final file path. Its folder is created if missing.
    suffix : str, optional
        Suffix for the temporary file (some writers infer the format from it).

    Yields
    ------
    pathlib.Path
        Where the caller writes; removed if the body raises.
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(
            prefix=f".{path.name}.", suffix=suffix or ".tmp", dir=path.parent
        )
    except OSError as exc:
        raise InputError(f"cannot write {path}: {exc.strerror or exc}") from None
    os.close(fd)
    tmp = Path(tmp)
    try:
        yield tmp
        os.chmod(tmp, _new_file_mode())  # mkstemp makes owner-only files; use the umask
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def _new_file_mode():
    """Permissions an ordinary new file gets under the current umask."""
    mask = os.umask(0o022)
    os.umask(mask)
    return 0o666 & ~mask


def write_text(path, text):
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def write_json(path, data):
    """Write ``data`` as indented JSON to ``path`` atomically (NaN is refused)."""
    write_text(path, json.dumps(data, indent=2, allow_nan=False) + "\n")


def read_text(path):
    """Read a UTF-8 text file; an unreadable or non-text file is an InputError."""
    path = Path(path)
    try:
        return path.read_text(encoding="utf-8")
    except OSError as exc:
        raise InputError(f"cannot read {path}: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a UTF-8 text file") from None


def read_json(path):
    """Parse a JSON file; invalid JSON is an InputError naming the line."""
    try:
        return json.loads(read_text(path))
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: not valid JSON ({exc.msg} at line {exc.lineno})") from None


def read_toml(path):
    """Parse a TOML file (:mod:`tomllib`); invalid TOML is an InputError."""
    try:
        return tomllib.loads(read_text(path))
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: not valid TOML ({exc})") from None
