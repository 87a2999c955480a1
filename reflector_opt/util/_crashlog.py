"""The traceback of an internal error, kept in a log file for a bug report.

An unexpected exception is a bug, not the user's input: the command line prints one line
naming the error and this file, and exits with code 1 (docs/conventions.md).
"""

import os
import tempfile
import traceback
from datetime import UTC, datetime
from pathlib import Path


def log_folder():
    """Where crash logs go: ``$XDG_CACHE_HOME/reflector-opt`` (default ``~/.cache``).

    Falls back to a private folder of the temporary directory where the cache is not
    writable.

    Returns
    -------
    pathlib.Path
        An existing, writable folder.
    """
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    candidates = [
        Path(cache) / "reflector-opt",
        Path(tempfile.gettempdir()) / f"reflector-opt-{os.getuid()}",
    ]
    for folder in candidates:
        try:
            folder.mkdir(parents=True, exist_ok=True, mode=0o700)
        except OSError:
            continue
        if os.access(folder, os.W_OK):
            return folder
    return Path(tempfile.mkdtemp(prefix="reflector-opt-"))


def write_crash_log(exc, command):
    """Write the traceback of ``exc`` with the command line to a new log file.

    Parameters
    ----------
    exc : BaseException
        The exception, with its traceback.
    command : sequence of str
        The command line.

    Returns
    -------
    pathlib.Path
        The log file.
    """
    from reflector_opt import __version__

    now = datetime.now(UTC)
    text = (
        f"reflector-opt {__version__}, {now.isoformat(timespec='seconds')}\n"
        f"command: {' '.join(command)}\n\n"
        + "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
    )
    fd, path = tempfile.mkstemp(
        prefix=f"crash-{now:%Y%m%dT%H%M%S}-", suffix=".log", dir=log_folder(), text=True
    )
    with os.fdopen(fd, "w", encoding="utf-8") as handle:
        handle.write(text)
    return Path(path)
