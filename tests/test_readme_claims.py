"""What README.md says a command writes, and how it treats a folder, holds against a run on
the sample data (issue 37, item 7).

README said plan.csv held the errors (it holds the poses; the errors are in plan.json), that
output folders were "replaced whole" (export into optimise's folder keeps the report and
design beside the new parts) and did not say that --scheduler needs the ``dask`` extra.
The commands that take a minute or more (optimise, report, plan-calibration, tolerance,
sweep) run only with ``REFLECTOR_OPT_DOC_COMMANDS=all``, as the documented commands do.
"""

from __future__ import annotations

import csv
import json
import os
import re
import tomllib
from pathlib import Path

import pytest

from reflector_opt.cli import main

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
DATA = ROOT / "examples" / "data"
RUN_ALL = os.environ.get("REFLECTOR_OPT_DOC_COMMANDS") == "all"


def claimed_files():
    """Command -> the file names README's table after ``<!-- command-files -->`` gives it."""
    table = README.split("<!-- command-files -->", 1)[1].split("\n\n", 1)[0]
    claims = {}
    for row in table.strip().splitlines()[2:]:
        command, writes = (cell.strip() for cell in row.strip("|").split("|"))
        names = re.findall(r"`([\w.]+\.(?:json|csv|png|stl|3mf|md|html))`", writes)
        claims[command.strip("`")] = names
    return claims


CLAIMS = claimed_files()

#: The folder commands, as they are run here on the sample data (cheap ones by default).
RUNS = {
    "export": (["export", str(DATA / "design.json")], False),
    "plan-calibration": (["plan-calibration", str(DATA / "design.json")], True),
    "tolerance": (["tolerance", str(DATA / "design.json"), "--samples", "20"], True),
    "sweep": (
        ["sweep", str(DATA / "design.json"), "--vary", "reflector.radius_mm=8.4,8.5"],
        True,
    ),
    "report": (["report", str(DATA / "design.json")], True),
    "optimise": (["optimise"], True),
}


def test_the_table_names_every_command_that_writes():
    file_commands = {"calibrate", "estimate", "firmware", "fit-sensor", "record", "stream"}
    assert set(RUNS) | file_commands == set(CLAIMS)
    assert CLAIMS["plan-calibration"] == ["plan.json", "plan.png", "plan.csv"]


@pytest.mark.parametrize("command", sorted(RUNS))
def test_a_command_writes_what_readme_says_and_keeps_the_rest(command, tmp_path, capsys):
    argv, expensive = RUNS[command]
    if expensive and not RUN_ALL:
        pytest.skip("takes a minute or more; REFLECTOR_OPT_DOC_COMMANDS=all runs it")
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("the user's\n")  # a file of the user's, or another command's
    assert main([*argv, "-o", str(out), "-q"]) == 0
    manifest = json.loads((out / "manifest.json").read_text())
    written = {entry["path"] for entry in manifest["files"]}
    assert set(CLAIMS[command]) <= written, set(CLAIMS[command]) - written
    assert all((out / name).is_file() for name in CLAIMS[command])
    assert (out / "notes.txt").read_text() == "the user's\n"
    assert [entry["path"] for entry in manifest["kept"]] == ["notes.txt"]
    if command == "plan-calibration":
        with open(out / "plan.csv", newline="") as handle:
            assert next(csv.reader(handle)) == ["pose", "pitch_deg", "roll_deg"]  # poses
        assert "predictions" in json.loads((out / "plan.json").read_text())  # the errors


def test_export_into_optimises_folder_keeps_its_report_as_readme_says(tmp_path, capsys):
    """The folder is not "replaced whole": a report already there stays, listed as kept."""
    out = tmp_path / "cad_out"
    out.mkdir()
    for name in ("design.json", "report.md"):
        (out / name).write_text("from optimise\n")
    assert main(["export", str(DATA / "design.json"), "-o", str(out), "-q"]) == 0
    kept = [e["path"] for e in json.loads((out / "manifest.json").read_text())["kept"]]
    assert kept == ["design.json", "report.md"]
    assert "replaced whole" not in README
    assert "those kept (`kept`)" in README and "other files in it" in README


@pytest.mark.parametrize("command", ["calibrate", "estimate", "fit-sensor"])
def test_a_file_command_writes_its_one_file(command, tmp_path, capsys):
    coefficients = tmp_path / "coefficients.json"
    argv = {
        "calibrate": ["calibrate", str(DATA / "data.csv"), "--folds", "0"],
        "estimate": ["estimate", str(coefficients), str(DATA / "log.csv")],
        "fit-sensor": ["fit-sensor", str(DATA / "mirror.csv"), "--reflectance", "0.87"],
    }[command]
    if command == "estimate":
        assert main(["calibrate", str(DATA / "data.csv"), "-o", str(coefficients), "-q"]) == 0
    out = tmp_path / "written"
    assert main([*argv, "-o", str(out), "-q"]) == 0 and out.is_file()


def test_the_scheduler_is_said_to_need_the_dask_extra():
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert "dask" in extras["optional-dependencies"]
    assert "--scheduler" in README and "pip install '.[dask]'" in README
