"""Work done beside the main work on a second core: a result, or files kept aside.

:class:`BackgroundCall` runs a function in a forked process and hands its result back on
:meth:`~BackgroundCall.result`, so that on a machine with two cores the export proves the
clearance while it checks and serialises the parts. :class:`BackgroundFiles` runs a function
that writes files into a private folder the same way (the export draws its pictures while
the parts are checked); the files reach the output folder only when
:meth:`BackgroundFiles.collect` is called, and :meth:`~BackgroundFiles.close` without a
collect stops the process and leaves nothing behind.

The forked process dies with its parent (also on SIGKILL) and leaves Ctrl-C to it. Where
processes cannot be forked, or the forked process fails, the function runs in the caller
when its result is asked for, so its errors are raised there as they would be without the
background process.
"""

from __future__ import annotations

import multiprocessing
import os
import pickle
import shutil
import sys
import tempfile
from pathlib import Path

from reflector_opt.util.atomic import remove_leftovers, temporary_prefix
from reflector_opt.util.errors import InputError
from reflector_opt.util.workers import init_worker

__all__ = ["PRIVATE_NAME", "BackgroundCall", "BackgroundFiles"]

#: Name the private folders of :class:`BackgroundFiles` are temporary versions of.
PRIVATE_NAME = "reflector-opt-files"


def _run_quietly(call, sender, parent_pid):
    """Body of the forked process: ``call()``'s pickled result into ``sender``; any failure is
    its exit code, never a traceback (the caller runs ``call`` itself and raises the error)."""
    init_worker(parent_pid)
    try:
        data = pickle.dumps(call(), protocol=pickle.HIGHEST_PROTOCOL)
        sender.send_bytes(data)
        sender.close()
    except BaseException:
        os._exit(1)


class BackgroundCall:
    """Run ``call()`` in a forked process; :meth:`result` returns what it returned.

    Parameters
    ----------
    call : callable
        Called without arguments; its result must be picklable.
    """

    def __init__(self, call):
        self._call = call
        self._process = self._receiver = None
        if "fork" in multiprocessing.get_all_start_methods():
            # What the streams hold now would be written again by the forked process.
            sys.stdout.flush()
            sys.stderr.flush()
            context = multiprocessing.get_context("fork")
            self._receiver, sender = context.Pipe(duplex=False)
            self._process = context.Process(target=_run_quietly, args=(call, sender, os.getpid()))
            self._process.start()
            sender.close()

    def result(self):
        """Wait for the forked process and return ``call()``'s result.

        If the process could not be forked or failed, ``call()`` runs here, so that its
        exceptions are raised to the caller.
        """
        if self._process is not None:
            try:
                data = self._receiver.recv_bytes()
            except EOFError:  # the process failed before it sent a result
                data = None
            self.close()
            if data is not None:
                return pickle.loads(data)
        return self._call()

    def close(self):
        """Stop the process if it still runs."""
        if self._process is not None:
            if self._process.is_alive():
                self._process.terminate()
            self._process.join()
            self._process.close()
            self._receiver.close()
            self._process = self._receiver = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class BackgroundFiles:
    """Run ``make(folder)`` in a forked process; move its files out on :meth:`collect`.

    The private folder is a temporary folder (``.tmp-reflector-opt-files-XXXXXXXX``,
    :mod:`reflector_opt.util.atomic`), so that one left behind by a killed process is
    removed by the next run.

    Parameters
    ----------
    make : callable
        ``make(folder)`` writes files into the :class:`pathlib.Path` ``folder``.
    """

    def __init__(self, make):
        name = Path(tempfile.gettempdir()) / PRIVATE_NAME
        remove_leftovers(name)
        self._folder = Path(tempfile.mkdtemp(prefix=temporary_prefix(name), dir=name.parent))
        self._job = BackgroundCall(lambda: make(self._folder))

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
        self._job.result()
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
        self._job.close()
        shutil.rmtree(self._folder, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
