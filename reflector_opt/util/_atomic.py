"""Atomic output: temporary names the next run recognises, and folders swapped in whole.

A file is written to a temporary sibling (:func:`tempfile.mkstemp`) and put in place with
:func:`os.replace` (:func:`reflector_opt.util._fileio.atomic_path`). A command that writes
several files builds them in a temporary sibling folder (:func:`tempfile.mkdtemp`,
:func:`atomic_folder`) and swaps it in at the end, so a reader sees the previous complete
set or the new complete set, never a mix; ``manifest.json`` in the folder lists the files
with their sizes and SHA-256 hashes, the command and the package version. Temporary names
are ``.tmp-NAME-XXXXXXXX``: a run that is killed leaves one behind, and the next write of
``NAME`` removes those last changed before it started (:func:`remove_leftovers`).
"""

import errno
import glob
import hashlib
import json
import os
import shutil
import tempfile
import time
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path

from reflector_opt.util._errors import InputError

#: Name of the manifest in every output folder.
MANIFEST = "manifest.json"

#: The start of every temporary name.
TEMP_MARK = ".tmp-"

#: When this process started writing (the import of this module), s since the epoch: a
#: temporary last changed before it is a killed run's leftover.
_STARTED = time.time()

#: Errors of the file system that mean "cannot write here", reported as bad input.
_CANNOT_WRITE = {
    errno.ENOSPC,
    errno.EDQUOT,
    errno.EROFS,
    errno.EACCES,
    errno.EPERM,
    errno.EFBIG,
    errno.ENOTDIR,
}


def temporary_prefix(path):
    """Prefix of a temporary sibling of ``path``: ``.tmp-NAME-``."""
    return f"{TEMP_MARK}{Path(path).name}-"


def remove_leftovers(path):
    """Remove the temporary siblings of ``path`` last changed before this process started.

    Parameters
    ----------
    path : str or pathlib.Path
        The target file or folder; its siblings ``.tmp-NAME-*`` older than this run are left
        by a run that was killed (a younger one is another write in progress).
    """
    path = Path(path)
    for left in path.parent.glob(glob.escape(temporary_prefix(path)) + "*"):
        try:
            if left.lstat().st_mtime < _STARTED:
                shutil.rmtree(left) if left.is_dir() and not left.is_symlink() else left.unlink()
        except OSError:  # removed meanwhile, or not ours to remove
            continue


def _remove_empty(folders):
    """Remove ``folders`` (innermost first) while each is empty."""
    for folder in folders:
        try:
            folder.rmdir()
        except FileNotFoundError:
            continue
        except OSError:  # something else was put there meanwhile: leave it and its parents
            return


@contextmanager
def new_parents(path):
    """Create the missing folders above ``path`` for one write; if it fails, remove them.

    A write that is refused or fails (an error, Ctrl-C) leaves no folder it created behind:
    folders exist only where something was written. Those that are no longer empty are
    kept.

    Parameters
    ----------
    path : str or pathlib.Path
        The file or folder about to be written.

    Raises
    ------
    InputError
        ``cannot write PATH: REASON``; where one of the parents is a file, it is named
        (``mkdir`` would say "File exists"). Nothing is left created.
    """
    path = Path(path)
    missing = [folder for folder in path.parents if not folder.is_dir()]  # innermost first
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        _remove_empty(missing)
        blocker = next((p for p in reversed(missing) if p.exists() and not p.is_dir()), None)
        reason = f"{blocker} is a file, not a folder" if blocker else exc.strerror or exc
        raise InputError(f"cannot write {path}: {reason}") from None
    try:
        yield
    except BaseException:
        _remove_empty(missing)
        raise


def cannot_write(path, exc):
    """The :class:`InputError` for an ``OSError`` that means ``path`` cannot be written, or None.

    A full disk, a quota, a read-only file system or a missing permission is the user's to
    fix: it is reported in one line. Any other ``OSError`` is not translated (None).
    """
    if isinstance(exc, OSError) and exc.errno in _CANNOT_WRITE:
        return InputError(f"cannot write {path}: {exc.strerror or exc}")
    return None


def _files(folder):
    """Every file below ``folder`` as sorted POSIX paths relative to it."""
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file())


def _entries(folder, names):
    return [
        {"path": n, "bytes": len(data), "sha256": hashlib.sha256(data).hexdigest()}
        for n in names
        for data in ((folder / n).read_bytes(),)
    ]


def _previous_outputs(folder, command):
    """Files the previous run of the same subcommand wrote into ``folder`` (to be replaced)."""
    try:
        manifest = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
        if manifest["command"][1:2] == list(command[1:2]):
            return {entry["path"] for entry in manifest["files"]}
    except (OSError, ValueError, TypeError, KeyError):  # none, or not one of ours
        pass
    return set()


def _link_or_copy(src, dst):
    try:
        os.link(src, dst)
    except OSError:
        shutil.copy2(src, dst)


def _carry_over(old, new, replaced):
    """Hard-link (or copy) into ``new`` what ``old`` holds that this run neither wrote nor
    replaces: files the user put there and the outputs of other commands."""
    kept = []
    for entry in sorted(old.iterdir()):
        name = entry.name
        if name == MANIFEST or name.startswith(TEMP_MARK) or (new / name).exists():
            continue
        if name in replaced:
            continue
        if entry.is_dir() and not entry.is_symlink():
            shutil.copytree(entry, new / name, symlinks=True, copy_function=_link_or_copy)
            kept += [f"{name}/{n}" for n in _files(new / name)]
        elif entry.is_symlink():
            os.symlink(os.readlink(entry), new / name)
        else:
            _link_or_copy(entry, new / name)
            kept.append(name)
    return kept


def _swap_in(new, target):
    """Put folder ``new`` at ``target``: the previous ``target`` (if any) is renamed aside,
    ``new`` renamed in its place and the previous one removed; if the second rename fails
    (or is interrupted), the previous one is put back."""
    aside = new.with_name(f"{new.name}-old")
    try:
        if target.exists():
            os.rename(target, aside)
        os.rename(new, target)
    except BaseException:
        if aside.exists() and not target.exists():
            os.rename(aside, target)
        raise
    shutil.rmtree(aside, ignore_errors=True)


def check_output_folder(path):
    """Refuse an output folder that is a file, the current folder or one of its parents, or
    a mount point.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    pathlib.Path

    Raises
    ------
    InputError
        Naming ``path`` and the problem. A mount point (``/proc``) cannot be renamed, and
        the folder is swapped in by renaming (:func:`atomic_folder`); one that
        :func:`os.path.ismount` misses (a bind mount) is refused when it is swapped.
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(f"{path}: exists and is not a folder")
    here, target = Path.cwd().resolve(), _resolved(path)
    if target == here or target in here.parents:
        raise InputError(
            f"{path}: is the current folder or holds it; give the outputs a folder of their own"
        )
    if os.path.ismount(path):
        raise _mount_point(path)
    return path


def _mount_point(path):
    """The refusal of an output folder that is a mount point."""
    return InputError(
        f"{path}: is a mount point, which cannot be replaced by renaming as an output folder "
        f"is; give a folder inside it (e.g. {Path(path) / 'out'})"
    )


def _resolved(path):
    """``path`` with its symbolic links followed; a loop of links is an InputError."""
    try:
        return path.resolve()
    except (RuntimeError, OSError):  # Python 3.11-3.12 raise RuntimeError for a loop
        raise InputError(f"{path}: a loop of symbolic links, not a folder to write") from None


def _write_manifest(path, work, command):
    """Carry the files of ``path`` this run keeps into ``work`` and write its manifest."""
    from reflector_opt import __version__

    written = _files(work)
    kept = _carry_over(path, work, _previous_outputs(path, command)) if path.is_dir() else []
    manifest = {
        "command": list(command),
        "version": __version__,
        "created": datetime.now(UTC).isoformat(timespec="seconds"),
        "files": _entries(work, written),
        "kept": _entries(work, kept),
    }
    (work / MANIFEST).write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")


def new_mode(mode):
    """``mode`` (e.g. ``0o666`` for a file) less the current umask: what ``open`` or
    ``mkdir`` would give, where :mod:`tempfile` makes files and folders the owner's alone."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mode & ~mask


@contextmanager
def atomic_folder(path, command):
    """Build an output folder in a temporary sibling and swap it in whole on success.

    Files already in ``path`` that this run does not write are kept (hard-linked into the
    new folder), except the outputs of the previous run of the same subcommand, which the
    new set replaces. ``manifest.json`` lists the files written (path, bytes, SHA-256), the
    files kept, the command, the package version and the time. If the body raises (an
    error, Ctrl-C), the temporary folder is removed and ``path`` is left as it was.

    Parameters
    ----------
    path : str or pathlib.Path
        The output folder; created if missing. It must not be a file, the current folder
        or one of its parents.
    command : sequence of str
        The command line, program name first and subcommand second (recorded in the
        manifest; a rerun of the same subcommand replaces the previous run's files).

    Yields
    ------
    pathlib.Path
        The temporary folder to write into.

    Raises
    ------
    InputError
        ``path`` is unsuitable (:func:`check_output_folder`; a mount point, which cannot be
        swapped), or the disk is full, read-only or not writable.
    """
    path = check_output_folder(path)
    if path.is_symlink():  # replace the folder it points to, and keep the link
        path = _resolved(path)
    with new_parents(path):
        remove_leftovers(path)
        try:
            work = Path(tempfile.mkdtemp(prefix=temporary_prefix(path), dir=path.parent))
        except OSError as exc:  # e.g. a read-only folder
            raise InputError(f"cannot write {path}: {exc.strerror or exc}") from None
        try:
            work.chmod(new_mode(0o777))
            yield work
            _write_manifest(path, work, command)
            _swap_in(work, path)
        except OSError as exc:
            if exc.errno in (errno.EBUSY, errno.EXDEV):  # a mount point ismount missed
                raise _mount_point(path) from None
            raise cannot_write(path, exc) or exc from None
        finally:
            shutil.rmtree(work, ignore_errors=True)
