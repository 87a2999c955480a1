"""The example notebooks run from top to bottom (in a scratch folder, on this checkout)."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "examples").glob("*.ipynb"))

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")


def test_notebooks_exist_and_are_committed_without_outputs():
    assert {p.name for p in NOTEBOOKS} >= {
        "paper_model_and_fig5.ipynb",
        "optimise_and_export.ipynb",
        "calibrate_from_csv.ipynb",
    }
    for path in NOTEBOOKS:
        book = nbformat.read(path, as_version=4)
        nbformat.validate(book)
        code = [c for c in book.cells if c.cell_type == "code"]
        assert code and all(not c.outputs and c.execution_count is None for c in code), path


#: Notebooks that take more than about ten seconds (18 s on 2 cores): marked ``slow``.
SLOW = {"optimise_and_export.ipynb"}


@pytest.mark.parametrize(
    "path",
    [pytest.param(p, marks=pytest.mark.slow) if p.name in SLOW else p for p in NOTEBOOKS],
    ids=lambda p: p.stem,
)
def test_notebook_runs(path, tmp_path, monkeypatch):
    # the kernel imports this checkout's package and writes its files into tmp_path
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    shutil.copy(path, tmp_path / path.name)
    book = nbformat.read(tmp_path / path.name, as_version=4)
    client = nbclient.NotebookClient(
        book, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()
    # every file the notebook writes goes under cad_out/, which git ignores
    assert {p.name for p in tmp_path.iterdir()} <= {path.name, "cad_out"}
    images = [
        o
        for c in book.cells
        if c.cell_type == "code"
        for o in c.outputs
        if "image/png" in o.get("data", {})
    ]
    assert images  # the figures display in the notebook


@pytest.mark.skipif(not (ROOT / ".git").exists(), reason="not a git checkout")
def test_outputs_are_ignored_by_git():
    outputs = ["cad_out/design.json", "cad_out/report/report.md", "examples/cad_out/x/data.csv"]
    done = subprocess.run(
        ["git", "check-ignore", *outputs], cwd=ROOT, capture_output=True, text=True, check=False
    )
    assert done.stdout.split() == outputs
    kept = subprocess.run(["git", "check-ignore", "cad_out/README.md"], cwd=ROOT, check=False)
    assert kept.returncode == 1  # the folder's README stays tracked
