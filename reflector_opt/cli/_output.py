"""What a subcommand shows besides its result: progress, log lines on stderr, and closing
lines naming the files it wrote with the command's wall time."""

import contextlib
import json
import logging
import sys
import time
from pathlib import Path

from reflector_opt.util._atomic import MANIFEST
from reflector_opt.util._progress import Progress


def print_json(summary):
    """Print a command's summary on stdout as indented JSON (``--json``).

    NumPy numbers and arrays become JSON numbers and lists, and a non-finite number (a
    resolution where the Jacobian is singular, a skipped figure) becomes ``null``
    (:func:`~reflector_opt.util._fileio.json_number`): JSON has no NaN or infinity, and a
    reader of the output should not have to accept them.
    """
    import numpy as np  # here, not at the top: `--help` loads no NumPy (tests/test_startup.py)

    from reflector_opt.util._fileio import json_number

    def plain(value):
        if isinstance(value, np.generic):
            value = value.item()
        if isinstance(value, dict):
            return {str(k): plain(v) for k, v in value.items()}
        if isinstance(value, (list, tuple, np.ndarray)):
            return [plain(v) for v in value]
        if isinstance(value, float):
            return json_number(value)
        if isinstance(value, Path):
            return str(value)
        return value

    print(json.dumps(plain(summary), indent=2, ensure_ascii=False))


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


def folder_lines(folder, files, started):
    """Closing lines of a command that writes an output folder: its files and its manifest.

    Parameters
    ----------
    folder : str or pathlib.Path
        The output folder (written whole, with ``manifest.json``:
        :mod:`reflector_opt.util._atomic`).
    files : iterable of str or pathlib.Path
        The files written, by name or path; each is listed in ``folder``.
    started : float
        ``time.perf_counter()`` when the command started, s.

    Returns
    -------
    str
    """
    folder = Path(folder)
    names = [Path(path).name for path in files]
    return written_lines([folder / name for name in [*names, MANIFEST]], started)


class _Formatter(logging.Formatter):
    """Progress and information as ``HH:MM:SS message``; warnings in the errors' style."""

    def __init__(self, prog):
        super().__init__("%(asctime)s %(message)s", "%H:%M:%S")
        self.prog = prog

    def format(self, record):
        if record.levelno >= logging.WARNING:
            return f"{self.prog}: {record.levelname.lower()}: {record.getMessage()}"
        return super().format(record)


class _Handler(logging.StreamHandler):
    """Writes above a progress bar when one is drawn (through ``tqdm.write``), and holds
    warnings until the command's input is accepted.

    Parameters
    ----------
    stream : file-like
        Where the lines go (stderr).
    level : int
        The least level shown; records below it only mark the command's work as begun.

    Notes
    -----
    A command's input is taken as accepted once its work begins (the first record below
    warning level: a progress report, shown or not; none with ``--quiet``) or once it
    returns. A warning logged before, while the input is read, is held till then, and
    dropped when the command fails instead, so that a refused input is one line alone
    (docs/conventions.md).
    """

    def __init__(self, stream, level):
        super().__init__(stream)
        self.shown = level
        self.held = []  # None once the input is accepted

    def emit(self, record):
        if self.held is not None:
            if record.levelno >= logging.WARNING:
                self.held.append(record)
                return
            self.accept()
        if record.levelno < self.shown:
            return
        tqdm = sys.modules.get("tqdm")  # loaded only once a bar has been drawn
        if tqdm is None:
            super().emit(record)
            return
        try:
            tqdm.tqdm.write(self.format(record), file=self.stream)
        except Exception:  # a log line must never stop the command
            self.handleError(record)

    def accept(self):
        """Show the warnings held so far, and every later one as it comes."""
        held, self.held = self.held or [], None
        for record in held:
            self.emit(record)


@contextlib.contextmanager
def console_logging(prog, quiet=False, verbose=0):
    """Send the package's log records to stderr for the time of one command.

    Warnings logged before the command's work begins are held until it begins or the command
    returns, and dropped if it fails first (:class:`_Handler`): a refused input is one line.

    Parameters
    ----------
    prog : str
        The command, e.g. ``"reflector-opt tolerance"``, named in warnings.
    quiet : bool
        Only warnings and errors (``--quiet``).
    verbose : int
        0: progress lines and each step; 1 or more (``-v``): also the details (DEBUG).
    """
    logger = logging.getLogger("reflector_opt")
    shown = logging.WARNING if quiet else logging.DEBUG if verbose else logging.INFO
    handler = _Handler(sys.stderr, shown)
    handler.setFormatter(_Formatter(prog))
    saved = logger.level, logger.propagate
    logger.addHandler(handler)
    logger.setLevel(logging.DEBUG)  # every record marks the work begun; the handler filters
    logger.propagate = False
    try:
        yield
        handler.accept()
    finally:
        logger.removeHandler(handler)
        logger.setLevel(saved[0])
        logger.propagate = saved[1]


def progress_for(args):
    """The progress display of a command: off with ``--quiet``."""
    return Progress(enabled=not args.quiet)


def add_console_arguments(parser):
    """``-q/--quiet`` and ``-v/--verbose``, which every subcommand takes."""
    parser.add_argument(
        "-q",
        "--quiet",
        action="store_true",
        help="no progress and no log lines, only warnings, errors and the result",
    )
    parser.add_argument(
        "-v",
        "--verbose",
        action="count",
        default=0,
        help="log each step's details too (progress is a bar on a terminal, else log lines)",
    )
