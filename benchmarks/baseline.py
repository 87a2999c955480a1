"""Run code against another commit of the package, for speed-ups measured as ratios in one run.

A benchmark keeps the code path it improves on as its reference by checking that commit out
in a temporary ``git worktree`` and running the same timing script in a fresh subprocess that
imports the checkout's own package, alternately with the working tree's.
"""

import json
import os
import subprocess
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


@contextmanager
def checkout(commit):
    """Yield the folder of a temporary, detached ``git worktree`` of ``commit``; remove it after."""
    with tempfile.TemporaryDirectory() as tmp:
        tree = Path(tmp) / "baseline"
        git = ["git", "-C", str(ROOT), "worktree"]
        subprocess.run([*git, "add", "--detach", "-q", str(tree), commit], check=True)
        try:
            yield tree
        finally:
            subprocess.run([*git, "remove", "--force", str(tree)], check=True)


def run_script(tree, script, *args, env=None):
    """Run ``script`` (Python source) with the package of ``tree`` importable; parse its JSON.

    The script runs in a fresh interpreter whose working folder and ``PYTHONPATH`` are
    ``tree`` and must print one JSON object on its last line of output, with the key
    ``"package"`` set to ``reflector_opt.__file__``; that it imported ``tree``'s own package
    is checked.

    Parameters
    ----------
    tree : path-like
        Root of a checkout (the repository itself or a :func:`checkout`).
    script : str
        Python source of the timing.
    *args : str
        Its command-line arguments (``sys.argv[1:]``).
    env : dict, optional
        Extra environment variables.

    Returns
    -------
    dict
        The JSON object the script printed last.
    """
    environment = {**os.environ, **(env or {}), "PYTHONPATH": str(tree)}
    done = subprocess.run(
        [sys.executable, "-c", script, *map(str, args)],
        cwd=tree,
        env=environment,
        capture_output=True,
        text=True,
        check=True,
    )
    result = json.loads(done.stdout.strip().splitlines()[-1])
    if not Path(result["package"]).resolve().is_relative_to(Path(tree).resolve()):
        raise RuntimeError(f"the script imported {result['package']}, not the package in {tree}")
    return result
