"""The compiled kernels import wherever the package lies, their disk cache or not.

numba refuses ``cache=True`` when neither the package's ``__pycache__`` nor the user's cache
folder is writable (a read-only installation, a read-only home). Each case runs a copy of
the package in a fresh interpreter whose ``__pycache__`` beside the kernels is a file (so it
cannot be a folder, even for root) and whose cache home is a file too.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "reflector_opt"

REPORT = """
import os, reflector_opt
from reflector_opt.model import _kernel as kernel
assert reflector_opt.__file__.startswith({root!r}), reflector_opt.__file__
print(kernel._OPTIONS["cache"], os.environ.get("NUMBA_CACHE_DIR"))
{extra}
"""


@pytest.fixture
def unwritable(tmp_path):
    """A copy of the package and a home where numba can cache nothing."""
    root = tmp_path / "site"
    shutil.copytree(PACKAGE, root / "reflector_opt", ignore=shutil.ignore_patterns("__pycache__"))
    (root / "reflector_opt" / "model" / "__pycache__").write_text("not a folder")
    blocked = tmp_path / "blocked"
    blocked.write_text("not a folder")
    (tmp_path / "tmp").mkdir()
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env.update(
        PYTHONPATH=str(root),
        PYTHONDONTWRITEBYTECODE="1",
        HOME=str(blocked),
        XDG_CACHE_HOME=str(blocked),
        TMPDIR=str(tmp_path / "tmp"),
    )
    return root, env, tmp_path / "tmp"


def _run(root, env, extra=""):
    code = REPORT.format(root=str(root), extra=extra)
    done = subprocess.run(
        [sys.executable, "-c", code],
        cwd=root,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.split("\n")


def test_the_cache_falls_back_to_a_private_temporary_folder(unwritable):
    root, env, tmp = unwritable
    extra = "import reflector_opt as ro; print(ro.voltages(ro.default_design(), 0.0, 0.0))"
    cache, folder = _run(root, env, extra)[0].split()
    assert cache == "True" and Path(folder).parent == tmp
    assert Path(folder).stat().st_mode & 0o077 == 0  # only this user
    assert list(Path(folder).rglob("*.nbi"))  # the compiled kernels were cached there


def test_without_any_writable_folder_the_kernels_are_compiled_uncached(unwritable):
    root, env, tmp = unwritable
    (tmp / f"reflector_opt-numba-{os.getuid()}").write_text("taken")
    assert _run(root, env)[0] == "False None"


def test_a_shared_temporary_folder_is_not_trusted(unwritable):
    root, env, tmp = unwritable
    shared = tmp / f"reflector_opt-numba-{os.getuid()}"
    shared.mkdir()
    shared.chmod(0o777)
    assert _run(root, env)[0] == "False None"


def test_an_unusable_numba_cache_dir_is_not_fatal(unwritable):
    root, env, _ = unwritable
    env["NUMBA_CACHE_DIR"] = env["HOME"]  # a file
    cache = _run(root, env)[0].split()[0]
    assert cache in ("True", "False")


@pytest.fixture
def installed(tmp_path):
    """A copy of the package as an installation would lay it out, and a writable cache home."""
    root = tmp_path / "site"
    shutil.copytree(PACKAGE, root / "reflector_opt", ignore=shutil.ignore_patterns("__pycache__"))
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env.update(PYTHONPATH=str(root), XDG_CACHE_HOME=str(tmp_path / "cache"))
    return root, env, tmp_path / "cache"


def test_the_cache_is_kept_in_the_users_cache_folder_never_beside_the_modules(installed):
    """Files beside the installed modules would outlive an uninstall and make the package an
    empty namespace package that hides a later editable install (pip install . then
    pip install -e .)."""
    root, env, cache = installed
    extra = "import reflector_opt as ro; print(ro.voltages(ro.default_design(), 0.0, 0.0))"
    flag, folder = _run(root, env, extra)[0].split()
    assert flag == "True" and Path(folder) == cache / "reflector_opt" / "numba"
    assert list(Path(folder).rglob("*.nbi"))
    beside = [p for p in (root / "reflector_opt").rglob("*") if p.suffix in (".nbi", ".nbc")]
    assert beside == []


def test_a_numba_cache_dir_of_the_users_is_kept(installed, tmp_path):
    root, env, _ = installed
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "mine")
    assert _run(root, env)[0].split() == ["True", str(tmp_path / "mine")]
