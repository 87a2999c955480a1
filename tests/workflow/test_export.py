"""``export``: the command's export as one library call, with what it wrote and said."""

import json

import pytest

from reflector_opt.cli import main
from reflector_opt.util._errors import InputError
from reflector_opt.workflow import ExportRun, export
from tests.cad.designs import DESIGN_A


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    out = tmp_path_factory.mktemp("export") / "parts"
    return export(DESIGN_A, part="reflector", chord_tolerance_mm=0.05, preview=False).write(out)


def test_the_run_lists_the_files_it_wrote(exported):
    assert isinstance(exported, ExportRun)
    names = sorted(f.name for f in exported.files)
    assert names == ["cad_report.json", "reflector.3mf", "reflector.stl"]
    assert all(f.is_file() and f.stat().st_size > 0 for f in exported.files)
    on_disk = sorted(p.name for p in exported.out.iterdir())
    assert on_disk == sorted([*names, "manifest.json"])  # nothing else, the manifest beside
    manifest = json.loads((exported.out / "manifest.json").read_text())
    assert manifest["command"][:2] == ["reflector_opt", "export"]


def test_the_text_names_each_check(exported):
    text = exported.text()
    triangles = exported.report["files"]["reflector"]["triangles"]
    assert f"reflector: {triangles} triangles" in text
    assert "reflector: printable; thinnest wall" in text
    assert "Eq 3 ray check:" in text and "collision-free over the workspace" in text
    assert exported.to_dict() is exported.report


def test_the_command_prints_the_runs_text(tmp_path, capsys):
    """The CLI parses, calls export and prints its text: the same lines."""
    out = tmp_path / "cli"
    design = tmp_path / "design.json"
    DESIGN_A.save(design)
    code = main(
        [
            "export",
            str(design),
            "-o",
            str(out),
            "--part",
            "reflector",
            "--chord-tolerance",
            "0.05",
            "--no-preview",
            "-q",
        ]
    )
    assert code == 0
    printed = capsys.readouterr().out
    run = export(design, part="reflector", chord_tolerance_mm=0.05, preview=False)
    run = run.write(tmp_path / "lib")
    assert printed.startswith(run.text() + "\n")


def test_an_unknown_part_is_refused_before_any_work(tmp_path):
    with pytest.raises(InputError, match=r"--part: expected one of 'all', .*, got 'lid'"):
        export(DESIGN_A, part="lid")
    assert not (tmp_path / "x").exists()
