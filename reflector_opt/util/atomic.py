"""Atomic output: temporary names the next run recognises, and folders swapped in whole.

A file is written to a temporary sibling and renamed into place
(:func:`reflector_opt.util.fileio.atomic_path`). A command that writes several files builds
them in a temporary sibling folder (:func:`atomic_folder`) and swaps it with the target at
the end, so a reader sees the previous complete set or the new complete set, never a mix;
``manifest.json`` in the folder lists the files with their sizes and SHA-256 hashes, the
command and the package version. Temporary names are ``.NAME.rotmp-PID-XXXX``: a run that
is killed leaves one behind, and the next write of ``NAME`` removes those whose process is
gone (:func:`remove_leftovers`).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import errno
import hashlib
import json
import os
import re
import secrets
import shutil
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path

from reflector_opt.util.errors import InputError

__all__ = [
    "MANIFEST",
    "TEMP_MARK",
    "atomic_folder",
    "cannot_write",
    "check_output_folder",
    "make_parent",
    "new_parents",
    "remove_leftovers",
    "temporary_prefix",
]

#: Name of the manifest in every output folder.
MANIFEST = "manifest.json"

#: What a temporary name holds between the target's name and the writing process's id.
TEMP_MARK = ".rotmp-"

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
    """Prefix of a temporary sibling of ``path`` written by this process: ``.NAME.rotmp-PID-``."""
    return f".{Path(path).name}{TEMP_MARK}{os.getpid()}-"


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def remove_leftovers(path):
    """Remove temporary siblings of ``path`` left by processes that no longer run.

    Parameters
    ----------
    path : str or pathlib.Path
        The target file or folder; its siblings ``.NAME.rotmp-PID-*`` of a finished process
        ``PID`` are removed (those of a running process are another write in progress).
    """
    path = Path(path)
    start = f".{path.name}{TEMP_MARK}"
    try:
        siblings = list(path.parent.iterdir())
    except OSError:
        return
    for sibling in siblings:
        if not sibling.name.startswith(start):
            continue
        pid = sibling.name[len(start) :].split("-", 1)[0]
        if pid.isdigit() and not _alive(int(pid)):
            if sibling.is_dir() and not sibling.is_symlink():
                shutil.rmtree(sibling, ignore_errors=True)
            else:
                sibling.unlink(missing_ok=True)


def make_parent(path):
    """Create the folder of ``path`` and its missing parents.

    Returns
    -------
    list of pathlib.Path
        The folders created, outermost first (:func:`new_parents` removes them again).

    Raises
    ------
    InputError
        ``cannot write PATH: REASON``; where one of the parents is a file, it is named
        (``mkdir`` would say "File exists"). Nothing is left created.
    """
    path = Path(path)
    created = []
    try:
        for folder in reversed(path.parents):
            if folder.is_dir():
                continue
            try:
                folder.mkdir()
            except FileExistsError:
                if not folder.is_dir():  # a file, or a link to none
                    raise
            else:
                created.append(folder)
    except OSError as exc:
        _remove_empty(created)
        blocker = next((p for p in reversed(path.parents) if p.exists() and not p.is_dir()), None)
        reason = f"{blocker} is a file, not a folder" if blocker else exc.strerror or exc
        raise InputError(f"cannot write {path}: {reason}") from None
    return created


def _remove_empty(folders):
    """Remove ``folders`` (outermost first) innermost first, while each is empty."""
    for folder in reversed(folders):
        try:
            folder.rmdir()
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
        A parent cannot be created (:func:`make_parent`).
    """
    created = make_parent(path)
    try:
        yield
    except BaseException:
        _remove_empty(created)
        raise


def cannot_write(path, exc):
    """The :class:`InputError` for an ``OSError`` that means ``path`` cannot be written, or None.

    A full disk, a quota, a read-only file system or a missing permission is the user's to
    fix: it is reported in one line. Any other ``OSError`` is not translated (None).
    """
    if isinstance(exc, OSError) and exc.errno in _CANNOT_WRITE:
        return InputError(f"cannot write {path}: {exc.strerror or exc}")
    return None


def _sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _files(folder):
    """Every file below ``folder`` as sorted POSIX paths relative to it."""
    return sorted(
        p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file() and p != folder
    )


def _entries(folder, names):
    return [
        {"path": n, "bytes": (folder / n).stat().st_size, "sha256": _sha256(folder / n)}
        for n in names
    ]


def _read_manifest(folder):
    """The manifest of a previous run in ``folder``, or None if absent or unreadable."""
    try:
        data = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def _previous_outputs(folder, command):
    """Files the previous run of the same subcommand wrote into ``folder`` (to be replaced)."""
    manifest = _read_manifest(folder)
    if manifest is None or manifest.get("command", [None, None])[1:2] != list(command[1:2]):
        return set()
    return {e.get("path") for e in manifest.get("files", []) if isinstance(e, dict)}


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
        if name == MANIFEST or TEMP_MARK in name or (new / name).exists() or name in replaced:
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


_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _exchange(a, b):
    """Swap two paths in one step (Linux ``renameat2``); False where it is not available."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or None, use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):
        return False
    renameat2.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p]
    renameat2.argtypes += [ctypes.c_uint]
    if renameat2(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):  # kernel or file system without it
        return False
    raise OSError(code, os.strerror(code), str(b))


def _swap_in(new, target):
    """Put folder ``new`` at ``target``; the previous ``target`` (if any) ends up at ``new``."""
    if not target.exists():
        os.rename(new, target)
        return False
    if not _exchange(new, target):
        old = target.with_name(f"{temporary_prefix(target)}{secrets.token_hex(4)}")
        os.rename(target, old)
        try:
            os.rename(new, target)
        except OSError:
            os.rename(old, target)
            raise
        os.rename(old, new)
    return True


def _swap(new, target):
    """:func:`_swap_in`, where a target that is a mount point the checks missed (it cannot be
    renamed: ``EBUSY``, or ``EXDEV`` across file systems) is refused as one."""
    try:
        _swap_in(new, target)
    except OSError as exc:
        if exc.errno in (errno.EBUSY, errno.EXDEV):
            raise _mount_point(target) from None
        raise


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
        Naming ``path`` and the problem. A mount point (``/proc``, a bind mount) cannot be
        renamed, and the folder is swapped in by renaming (:func:`atomic_folder`).
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(f"{path}: exists and is not a folder")
    here, target = Path.cwd().resolve(), _resolved(path)
    if target == here or target in here.parents:
        raise InputError(
            f"{path}: is the current folder or holds it; give the outputs a folder of their own"
        )
    if path.is_dir() and (os.path.ismount(path) or str(target) in _mount_points()):
        raise _mount_point(path)
    return path


#: The mount table of this process (Linux); elsewhere ``os.path.ismount`` alone.
_MOUNTINFO = Path("/proc/self/mountinfo")


def _mount_points():
    """Every mount point of this process's mount table, as paths; empty where there is none.

    ``os.path.ismount`` misses a bind mount of a folder of the same file system; the table
    lists it (the fifth field of each line, with space, tab, newline and backslash escaped
    in octal).
    """
    try:
        lines = _MOUNTINFO.read_text(encoding="utf-8", errors="surrogateescape").splitlines()
    except OSError:
        return set()
    fields = (line.split(" ") for line in lines)
    unescape = re.compile(r"\\([0-7]{3})")
    return {unescape.sub(lambda m: chr(int(m.group(1), 8)), f[4]) for f in fields if len(f) > 4}


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
        try:
            remove_leftovers(path)
            work = path.with_name(f"{temporary_prefix(path)}{secrets.token_hex(4)}")
            work.mkdir()
        except OSError as exc:  # e.g. a read-only folder
            raise InputError(f"cannot write {path}: {exc.strerror or exc}") from None
        try:
            yield work
            _write_manifest(path, work, command)
            _swap(work, path)
        except OSError as exc:
            raise cannot_write(path, exc) or exc from None
        finally:
            if work.exists():
                shutil.rmtree(work, ignore_errors=True)
