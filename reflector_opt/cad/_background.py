"""Work done beside the main work on a second core: a result, or files kept aside.

:class:`BackgroundCall` runs a function in a forked worker of a one-process pool
(:func:`~reflector_opt.util._pools.local_processes`) and hands its result back on
:meth:`~BackgroundCall.result`, so that on a machine with two cores the export proves the
clearance while it checks and serialises the parts. :class:`BackgroundFiles` runs a function
that writes files into a private folder the same way (the export draws its pictures while
the parts are checked); the files reach the output folder only when
:meth:`BackgroundFiles.collect` is called, and :meth:`~BackgroundFiles.close` without a
collect stops the process and leaves nothing behind.

The worker dies with its parent (also on SIGKILL) and leaves Ctrl-C to it. Where workers are
not forked (:data:`~reflector_opt.util._pools.START_METHOD`: the function, often a closure,
reaches a forked worker without being pickled), or the worker fails, the function runs in
the caller when its result is asked for, so its errors are raised there as they would be
without the background process.
"""

import contextlib
import shutil
import sys
import tempfile
from pathlib import Path

from reflector_opt.util import _pools as pools
from reflector_opt.util._atomic import remove_leftovers, temporary_prefix
from reflector_opt.util._errors import InputError

#: Name the private folders of :class:`BackgroundFiles` are temporary versions of.
PRIVATE_NAME = "reflector-opt-files"

#: The calls of the background workers being started, by key: a forked worker has them.
_CALLS = {}


def _run(key):
    """Body of the background worker: the call it was forked for."""
    return _CALLS[key]()


class BackgroundCall:
    """Run ``call()`` in a forked worker; :meth:`result` returns what it returned.

    Parameters
    ----------
    call : callable
        Called without arguments; its result must be picklable.
    """

    def __init__(self, call):
        self._call = call
        self._pool = contextlib.ExitStack()
        self._future = None
        if pools.START_METHOD == "fork":
            # What the streams hold now would be written again by the forked process.
            sys.stdout.flush()
            sys.stderr.flush()
            _CALLS[id(self)] = call
            try:  # the pool forks its worker as it starts
                self._executor = self._pool.enter_context(pools.local_processes(1)())
            finally:
                del _CALLS[id(self)]
            self._future = self._executor.submit(_run, id(self))

    def result(self):
        """Wait for the worker and return ``call()``'s result.

        If the worker could not be started or failed, ``call()`` runs here, so that its
        exceptions are raised to the caller.
        """
        if self._future is not None:
            try:
                return self._future.result()
            except Exception:  # raised again by the call here
                pass
            finally:
                self.close()
        return self._call()

    def close(self):
        """Stop the worker if it still runs."""
        if self._future is not None and not self._future.done():
            pools.stop(self._executor)
        self._future = None
        self._pool.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class BackgroundFiles:
    """Run ``make(folder)`` in a forked process; move its files out on :meth:`collect`.

    The private folder is a temporary folder (``.tmp-reflector-opt-files-XXXXXXXX``,
    :mod:`reflector_opt.util._atomic`), so that one left behind by a killed process is
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
        reflector_opt.util._errors.InputError
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
