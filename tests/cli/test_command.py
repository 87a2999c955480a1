"""``cli.command``: a workflow called as a command calls it, and its run printed."""

import argparse
import json
import time
from pathlib import Path

import pytest

from reflector_opt.cli._command import call_into_folder, print_run
from reflector_opt.util._errors import InputError


class _Run:
    files = (Path("out/a.csv"), Path("out/b.png"))

    def text(self):
        return "the run's text"

    def to_dict(self):
        return {"value": float("nan"), "files": [str(f) for f in self.files]}


def _args(**kwargs):
    return argparse.Namespace(json=False, started=time.perf_counter(), **kwargs)


def test_print_run_prints_the_text_then_the_files(capsys):
    assert print_run(_args(), _Run(), ["out/x.json"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "the run's text"
    assert lines[1].startswith("wrote 1 file in ") and lines[2:] == ["  out/x.json"]


def test_print_run_lists_a_folder_with_its_manifest(capsys):
    print_run(_args(), _Run(), folder="elsewhere")
    lines = capsys.readouterr().out.splitlines()
    assert lines[1].startswith("wrote 3 files in ")
    assert lines[2:] == ["  elsewhere/a.csv", "  elsewhere/b.png", "  elsewhere/manifest.json"]


def test_print_run_prints_json_alone(capsys):
    args = _args()
    args.json = True
    assert print_run(args, _Run(), folder="out") == 0
    assert json.loads(capsys.readouterr().out) == {
        "value": None,
        "files": ["out/a.csv", "out/b.png"],
    }


def test_call_into_folder_makes_the_run_then_writes_it_into_the_folder(tmp_path):
    seen = []

    class Run:
        def write(self, folder, *, command):
            seen.append(("write", folder, command))
            return "written"

    def workflow(a, b, *, progress, option):
        seen.append(("run", a, b, option))
        progress(0.5, "half")
        return Run()

    args = _args(out=str(tmp_path / "o"), quiet=True, argv=["reflector-opt", "x"])
    assert call_into_folder(args, workflow, 1, 2, option=3) == "written"
    assert seen == [("run", 1, 2, 3), ("write", tmp_path / "o", args.argv)]


def test_call_into_folder_refuses_the_folder_before_any_work(tmp_path):
    (tmp_path / "file").write_text("")
    args = _args(out=str(tmp_path / "file"), quiet=True, argv=["reflector-opt", "x"])

    def workflow(**_):
        raise AssertionError("called")

    with pytest.raises(InputError, match=r"^--out .*file: exists and is not a folder"):
        call_into_folder(args, workflow)
