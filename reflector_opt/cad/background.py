"""Files made beside the main work, kept aside until the work says they may be written.

:class:`BackgroundFiles` runs a function that writes files into a private folder in a forked
process, so that on a machine with two cores it runs while the caller goes on (the export
draws its pictures while the parts are checked). The files reach the output folder only when
:meth:`BackgroundFiles.collect` is called; :meth:`BackgroundFiles.close` without a collect
stops the process and leaves nothing behind. Where processes cannot be forked, or the forked
process fails, the function runs in the caller at :meth:`~BackgroundFiles.collect`, so its
errors are raised there as they would be without the background process.
"""

from __future__ import annotations

import multiprocessing
import os
import shutil
import sys
import tempfile
from pathlib import Path

from reflector_opt.util.errors import InputError
from reflector_opt.util.workers import init_worker

__all__ = ["BackgroundFiles"]


def _quietly(make, parent_pid):
    """``make`` for a forked process that dies with its parent (also on SIGKILL) and ignores
    Ctrl-C (the parent handles it and stops the process): any failure is its exit code,
    never a traceback."""

    def run(folder):
        init_worker(parent_pid)
        try:
            make(folder)
        except BaseException:  # the caller runs ``make`` itself and raises the error
            os._exit(1)

    return run


class BackgroundFiles:
    """Run ``make(folder)`` in a forked process; move its files out on :meth:`collect`.

    Parameters
    ----------
    make : callable
        ``make(folder)`` writes files into the :class:`pathlib.Path` ``folder``.
    """

    def __init__(self, make):
        self._make = make
        self._folder = Path(tempfile.mkdtemp(prefix="reflector-opt-"))
        self._process = None
        if "fork" in multiprocessing.get_all_start_methods():
            # What the streams hold now would be written again by the forked process.
            sys.stdout.flush()
            sys.stderr.flush()
            context = multiprocessing.get_context("fork")
            self._process = context.Process(
                target=_quietly(make, os.getpid()), args=(self._folder,)
            )
            self._process.start()

    def collect(self, out_dir, names):
        """Wait for the files and move them into ``out_dir``.

        Parameters
        ----------
        out_dir : pathlib.Path
            Output folder (created if missing).
        names : sequence of str
            File names ``make`` writes.

        Returns
        -------
        dict of str to pathlib.Path
            Each name's path in ``out_dir``.

        Raises
        ------
        reflector_opt.util.errors.InputError
            A file cannot be moved into ``out_dir`` (and what ``make`` raises).
        """
        if self._process is not None:
            self._process.join()
        if self._process is None or self._process.exitcode != 0:
            self._make(self._folder)
        paths = {}
        try:
            out_dir.mkdir(parents=True, exist_ok=True)
            for name in names:
                paths[name] = Path(shutil.move(self._folder / name, out_dir / name))
        except OSError as exc:
            raise InputError(f"cannot write {out_dir}: {exc.strerror or exc}") from None
        return paths

    def close(self):
        """Stop the process if it still runs, and remove the private folder."""
        if self._process is not None:
            if self._process.is_alive():
                self._process.terminate()
            self._process.join()
            self._process.close()
            self._process = None
        shutil.rmtree(self._folder, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
