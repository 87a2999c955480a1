"""Atomic output folders: the old complete set or the new one, a manifest, no leftovers."""

import errno
import hashlib
import json
import os

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from reflector_opt import __version__
from reflector_opt.util._atomic import (
    MANIFEST,
    TEMP_MARK,
    atomic_folder,
    check_output_folder,
    remove_leftovers,
)
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import atomic_path, write_text

COMMAND = ["reflector-opt", "report", "design.json"]


def _contents(folder):
    return {
        p.relative_to(folder).as_posix(): p.read_bytes() for p in folder.rglob("*") if p.is_file()
    }


def _write_set(folder, names, text):
    for name in names:
        write_text(folder / name, f"{text} {name}")


def _no_temporaries(parent):
    return [p.name for p in parent.iterdir() if TEMP_MARK in p.name] == []


def test_a_new_folder_gets_the_files_and_a_manifest_of_them(tmp_path):
    out = tmp_path / "out"
    with atomic_folder(out, COMMAND) as work:
        assert work.parent == tmp_path and TEMP_MARK in work.name and not out.exists()
        _write_set(work, ["a.txt", "b.txt"], "new")
    manifest = json.loads((out / MANIFEST).read_text())
    assert manifest["command"] == COMMAND and manifest["version"] == __version__
    assert [e["path"] for e in manifest["files"]] == ["a.txt", "b.txt"]
    for entry in manifest["files"]:
        data = (out / entry["path"]).read_bytes()
        assert entry["bytes"] == len(data) == len(f"new {entry['path']}")
        assert entry["sha256"] == hashlib.sha256(data).hexdigest()
    assert manifest["kept"] == []
    assert _no_temporaries(tmp_path)


def test_a_failure_leaves_the_previous_set_untouched(tmp_path):
    out = tmp_path / "out"
    with atomic_folder(out, COMMAND) as work:
        _write_set(work, ["a.txt", "b.txt"], "old")
    before = _contents(out)
    with pytest.raises(RuntimeError, match="half-way"), atomic_folder(out, COMMAND) as work:
        _write_set(work, ["a.txt"], "new")
        raise RuntimeError("half-way")
    assert _contents(out) == before
    assert _no_temporaries(tmp_path)


@settings(max_examples=25, deadline=None)
@given(stop=st.integers(0, 5))
def test_an_interrupt_at_any_point_leaves_the_old_or_the_new_set(tmp_path_factory, stop):
    tmp_path = tmp_path_factory.mktemp("interrupt")
    out = tmp_path / "out"
    names = [f"f{i}.txt" for i in range(5)]
    with atomic_folder(out, COMMAND) as work:
        _write_set(work, names, "old")
    old = _contents(out)
    try:
        with atomic_folder(out, COMMAND) as work:
            for i, name in enumerate(names):
                if i == stop:
                    raise KeyboardInterrupt
                write_text(work / name, f"new {name}")
    except KeyboardInterrupt:
        assert _contents(out) == old
    else:
        assert {k: v for k, v in _contents(out).items() if k != MANIFEST} == {
            n: f"new {n}".encode() for n in names
        }
    assert _no_temporaries(tmp_path)


def test_a_rerun_replaces_its_own_outputs_and_keeps_the_rest(tmp_path):
    out = tmp_path / "out"
    with atomic_folder(out, ["reflector-opt", "optimise"]) as work:
        _write_set(work, ["design.json", "report.md", "stale.png"], "optimise")
    (out / "notes.txt").write_text("mine")
    with atomic_folder(out, ["reflector-opt", "report", "x"]) as work:
        _write_set(work, ["report.md"], "report")
    # another command's outputs and the user's file are kept, hard-linked
    assert (out / "design.json").read_text() == "optimise design.json"
    assert (out / "stale.png").exists() and (out / "notes.txt").read_text() == "mine"
    assert (out / "report.md").read_text() == "report report.md"
    manifest = json.loads((out / MANIFEST).read_text())
    assert [e["path"] for e in manifest["files"]] == ["report.md"]
    assert [e["path"] for e in manifest["kept"]] == ["design.json", "notes.txt", "stale.png"]
    with atomic_folder(out, ["reflector-opt", "report", "x"]) as work:
        _write_set(work, ["report.html"], "report")
    # the previous report run's report.md is replaced by this run's set (without it)
    assert not (out / "report.md").exists() and (out / "notes.txt").exists()
    assert (out / "design.json").exists()


def test_a_link_to_a_folder_stays_a_link_to_the_new_set(tmp_path):
    real = tmp_path / "real"
    with atomic_folder(real, COMMAND) as work:
        _write_set(work, ["a.txt"], "old")
    link = tmp_path / "link"
    link.symlink_to(real)
    with atomic_folder(link, COMMAND) as work:
        _write_set(work, ["a.txt"], "new")
    assert link.is_symlink() and (link / "a.txt").read_text() == "new a.txt"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "real"]


def test_the_current_folder_and_files_are_refused(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for target in (".", tmp_path.parent):
        with pytest.raises(InputError, match="current folder"), atomic_folder(target, COMMAND):
            pass
    (tmp_path / "file").write_text("x")
    with pytest.raises(InputError, match="not a folder"), atomic_folder("file", COMMAND):
        pass


def test_an_output_under_a_file_names_the_file(tmp_path):
    """'cannot write a/file/out: File exists' (mkdir's reason) did not say what was wrong."""
    from reflector_opt.util._fileio import write_text

    (tmp_path / "file").write_text("x")
    message = f"^cannot write {tmp_path}/file/sub/out: {tmp_path}/file is a file, not a folder$"
    with (
        pytest.raises(InputError, match=message),
        atomic_folder(tmp_path / "file/sub/out", COMMAND),
    ):
        pass
    with pytest.raises(InputError, match=message):
        write_text(tmp_path / "file/sub/out", "new")
    assert (tmp_path / "file").read_text() == "x" and len(list(tmp_path.iterdir())) == 1


def test_a_loop_of_links_is_refused_as_an_output_folder(tmp_path):
    """optimise -o LOOP ended in an internal error (RuntimeError: Symlink loop)."""
    loop = tmp_path / "loop"
    loop.symlink_to("loop")
    with pytest.raises(InputError, match=f"^{loop}: a loop of symbolic links, not a folder"):
        with atomic_folder(loop, COMMAND):
            pass
    assert [p.name for p in tmp_path.iterdir()] == ["loop"] and loop.is_symlink()


def test_leftovers_older_than_this_run_are_removed(tmp_path):
    """A run killed outright leaves its temporary behind; the next write of the same
    target removes it, but not a younger one (another write in progress) nor another
    target's."""
    old = tmp_path / f"{TEMP_MARK}out-abcd1234"
    old.mkdir()
    (old / "half.txt").write_text("half")
    young = tmp_path / f"{TEMP_MARK}out-efgh5678"
    young.mkdir()
    other = tmp_path / f"{TEMP_MARK}other-abcd1234"
    other.write_text("another target's")
    for left in (old, other):
        os.utime(left, (0, 0))  # last changed in 1970, before this run
    remove_leftovers(tmp_path / "out")
    assert not old.exists() and young.exists() and other.exists()
    os.utime(young, (0, 0))
    write_text(tmp_path / "out", "complete")  # a file's write removes them too
    assert sorted(p.name for p in tmp_path.iterdir()) == [other.name, "out"]


@pytest.mark.parametrize("code", [errno.ENOSPC, errno.EROFS, errno.EACCES])
def test_a_full_or_read_only_disk_is_one_input_error_and_leaves_the_old_set(
    tmp_path, monkeypatch, code
):
    out = tmp_path / "out"
    with atomic_folder(out, COMMAND) as work:
        _write_set(work, ["a.txt"], "old")
    before = _contents(out)

    def full(*args, **kwargs):
        raise OSError(code, os.strerror(code))

    message = f"cannot write .*{os.strerror(code)}"
    with pytest.raises(InputError, match=message):
        with atomic_folder(out, COMMAND) as work:
            monkeypatch.setattr("pathlib.Path.write_text", full)
            (work / "a.txt").write_text("new")
    monkeypatch.undo()
    assert _contents(out) == before and _no_temporaries(tmp_path)
    with pytest.raises(InputError, match=message), atomic_path(out / "a.txt") as tmp:
        monkeypatch.setattr("pathlib.Path.write_text", full)
        tmp.write_text("new")
    monkeypatch.undo()
    assert _contents(out) == before and _no_temporaries(out)


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_parent_is_one_input_error(tmp_path):
    parent = tmp_path / "ro"
    parent.mkdir()
    parent.chmod(0o500)
    try:
        with pytest.raises(InputError, match=r"cannot write .*Permission denied"):
            with atomic_folder(parent / "out", COMMAND):
                pass
        with pytest.raises(InputError, match=r"cannot write .*Permission denied"):
            write_text(parent / "a.txt", "x")
    finally:
        parent.chmod(0o700)
    assert list(parent.iterdir()) == []


@pytest.mark.parametrize("stop", [InputError("refused"), KeyboardInterrupt()], ids=repr)
def test_a_refused_write_leaves_no_folder_it_made(tmp_path, stop):
    """estimate made new/sub/ for its angles, refused the log and left new/sub/ behind."""
    (tmp_path / "old").mkdir()
    for target in (tmp_path / "new/sub/angles.csv", tmp_path / "old/new/sub/angles.csv"):
        with pytest.raises(type(stop)), atomic_path(target) as tmp:
            assert tmp.parent.is_dir()
            raise stop
    with pytest.raises(type(stop)), atomic_folder(tmp_path / "new/sub/out", COMMAND):
        raise stop
    assert [p.name for p in tmp_path.iterdir()] == ["old"] and not any((tmp_path / "old").iterdir())
    write_text(tmp_path / "new/sub/angles.csv", "written")  # made when something is written
    assert (tmp_path / "new/sub/angles.csv").read_text() == "written"


def test_a_folder_made_for_a_write_is_kept_once_it_holds_something_else(tmp_path):
    with pytest.raises(InputError), atomic_path(tmp_path / "new/sub/a.csv"):
        (tmp_path / "new/b.csv").write_text("another writer's")
        raise InputError("refused")
    assert [p.name for p in (tmp_path / "new").iterdir()] == ["b.csv"]


def test_a_mount_point_is_refused_as_an_output_folder(tmp_path, monkeypatch):
    """-o /proc was an internal error ('Device or resource busy') after all the work."""
    mount = tmp_path / "mnt"
    mount.mkdir()
    monkeypatch.setattr(os.path, "ismount", lambda path: str(path) == str(mount))
    message = f"^{mount}: is a mount point, .* give a folder inside it \\(e.g. {mount}/out\\)$"
    with pytest.raises(InputError, match=message), atomic_folder(mount, COMMAND):
        pytest.fail("the body ran")
    assert check_output_folder(mount / "out") == mount / "out"
    assert [p.name for p in tmp_path.iterdir()] == ["mnt"]


def test_an_interrupt_between_the_renames_of_the_swap_puts_the_old_set_back(tmp_path, monkeypatch):
    """The new set goes in by two renames (the old set aside, the new one in its place):
    an interrupt after the first leaves the old set where it was."""
    out = tmp_path / "out"
    with atomic_folder(out, COMMAND) as work:
        _write_set(work, ["a.txt"], "old")
    before = _contents(out)
    rename, calls = os.rename, []

    def interrupted(src, dst):
        calls.append(src)
        if len(calls) == 2:
            raise KeyboardInterrupt
        rename(src, dst)

    monkeypatch.setattr(os, "rename", interrupted)
    with pytest.raises(KeyboardInterrupt), atomic_folder(out, COMMAND) as work:
        _write_set(work, ["a.txt", "b.txt"], "new")
    assert calls[0] == out  # the old set was moved aside first
    assert _contents(out) == before and _no_temporaries(tmp_path)


@pytest.mark.parametrize("code", [errno.EBUSY, errno.EXDEV])
def test_a_mount_point_the_checks_miss_is_refused_at_the_swap(tmp_path, monkeypatch, code):
    out = tmp_path / "out"
    with atomic_folder(out, COMMAND) as work:
        _write_set(work, ["a.txt"], "old")
    before = _contents(out)

    rename = os.rename

    def busy(src, dst):  # a bind mount, which os.path.ismount does not see, cannot be renamed
        if src == out:
            raise OSError(code, os.strerror(code), str(out))
        rename(src, dst)

    monkeypatch.setattr(os, "rename", busy)
    with pytest.raises(InputError, match=f"^{out}: is a mount point"):
        with atomic_folder(out, COMMAND) as work:
            _write_set(work, ["a.txt"], "new")
    assert _contents(out) == before and _no_temporaries(tmp_path)
