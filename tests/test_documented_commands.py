"""Every ``reflector-opt`` command that README.md and docs/*.md show runs as written.

A documented command is a line that begins ``reflector-opt`` in a ```sh block, or ``$
reflector-opt`` (a transcript) in any block, its ``\\`` continuations joined. Each runs
in-process (:func:`reflector_opt.cli.main`) in a scratch folder holding a copy of
``examples/`` (the sample data of examples/data and the example configs), the paths as the
docs write them, from the repository root. A file the command names must be in that copy or be
written by an earlier command of the same page (which is run first, once per session); the
command must exit 0 and leave the output it names (``-o``, or the option's default).

Commands marked :data:`EXPENSIVE` (with what one took on the 2-core development machine
under load) are, by default, parsed by the command line's own parser and their named files
checked, not run; ``REFLECTOR_OPT_DOC_COMMANDS=all`` runs them too. Lines in :data:`SKIPPED`
are illustrative and never run, each for the reason given. The sample data themselves are
checked to be what ``examples/make_sample_data.py`` writes, number by number within the
tolerances of ``tests/test_outputs_unchanged.py`` (the committed files were written on
another machine, whose arithmetic rounds the last digits differently).
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
import os
import re
import shlex
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from reflector_opt.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^( *)```(\w*)\n(.*?)^\1```", re.MULTILINE | re.DOTALL)
FILE_ARG = re.compile(r"[\w./-]+\.(?:json|csv|toml)")
OUTPUT_OPTIONS = {"-o", "--out", "--output"}
WRITE_DESIGNS = {"optimise", "correct"}  # a design.json in the output folder
RUN_ALL = os.environ.get("REFLECTOR_OPT_DOC_COMMANDS") == "all"

#: Lines never run, and why.
SKIPPED = {
    "reflector-opt optimise --starts 8 --scheduler tcp://host:8786": "a Dask scheduler's address",
    "reflector-opt optimise --sensor auto --scheduler tcp://host:8786": (
        "a Dask scheduler's address"
    ),
    "reflector-opt tolerance cad_out/design.json --scheduler tcp://head:8786": (
        "a Dask scheduler's address"
    ),
    "reflector-opt tolerance examples/data/design.json --scheduler tcp://10.0.0.5:8786": (
        "a Dask scheduler's address"
    ),
    "reflector-opt tolerance examples/data/design.json --samples 20000 --scheduler "
    "tcp://HEAD:8786": "a Dask scheduler's address",
    "reflector-opt optimise --tolerances examples/tolerance.toml --scheduler tcp://HEAD:8786": (
        "a Dask scheduler's address"
    ),
}

#: Commands run only with REFLECTOR_OPT_DOC_COMMANDS=all, with the wall seconds one run took
#: here (2 cores shared with other work, load average 0.4–10; a run that needed an earlier
#: command includes it).
EXPENSIVE = {
    "reflector-opt optimise": 21,  # docs/performance-optimise.md, end to end
    "reflector-opt optimise --surface polished": 30,
    "reflector-opt optimise --config examples/optimise.toml -o cad_out/a --seed 3 --pareto": 70,
    "reflector-opt optimise --starts 4 --workers 2": 22,
    "reflector-opt optimise --config examples/optimise.toml -o cad_out/a --seed 3": 26,
    "reflector-opt optimise --sensor VCNT2020": 27,
    "reflector-opt optimise --pareto": 49,
    "reflector-opt optimise --tolerances examples/tolerance.toml": 18,
    "reflector-opt optimise --tolerances examples/tolerance.toml --pareto": 163,
    "reflector-opt optimise --pareto --tolerances examples/tolerance.toml --no-report": 40,
    "reflector-opt optimise --pareto --tolerances examples/tolerance.toml --no-report --quiet": 38,
    "reflector-opt optimise --sensor auto": 13,
    "reflector-opt optimise --objective resolution": 24,
    "reflector-opt optimise --read-out stated": 43,
    "reflector-opt optimise --sensor auto --no-report": 5,
    "reflector-opt optimise --sensor NJL5901R-2,VCNT2020 --workers 2": 17,
    "reflector-opt plan-calibration examples/data/design.json -o cad_out/plan": 61,
    "reflector-opt calibrate examples/data/data.csv --design examples/data/design.json "
    "--model physical -o cad_out/coefficients.json": 11,
    "reflector-opt identify examples/data/data.csv --design examples/data/design.json "
    "--curve 1:S1=examples/data/s1.csv -o cad_out/AS_BUILT.json": 66,
    "reflector-opt identify examples/data/data.csv --design examples/data/design.json "
    "--curve 1:S1=examples/data/s1.csv --curve 1:S2=examples/data/s2.csv "
    "-o cad_out/AS_BUILT.json": 51,
    "reflector-opt identify examples/data/data.csv --design examples/data/design.json "
    "--batch B1 -o cad_out/AS_BUILT.json": 57,
    "reflector-opt report examples/data/design.json --as-built cad_out/AS_BUILT.json": 89,
    "reflector-opt tolerance cad_out/design.json --samples 1000 -o cad_out/tol": 42,
    "reflector-opt tolerance examples/data/design.json": 31,
    "reflector-opt tolerance examples/data/design.json --samples 2000 --seed 3 -o cad_out/tol "
    "--tolerances examples/tolerance.toml": 61,
    "reflector-opt sweep examples/data/design.json --vary reflector.radius_mm=8.35:8.55:5 "
    "--samples 50": 11,
    "reflector-opt sweep examples/data/design.json --vary reflector.centre_mm[2]=0.6,0.75,0.9 "
    "--vary sensors[0].position_mm[0]=7.3:7.4:3": 45,
}

#: Commands that need an optional extra the test install leaves out: the module it brings.
NEEDS = {"--format step": "build123d"}

#: Commands run by default that take more than about ten seconds, with the wall seconds of one
#: run on the 2-core machine (``--durations=0`` of a full run): their tests, and the tests of
#: the commands that read what they write, are marked ``slow``.
SLOW = {
    "reflector-opt identify examples/data/data.csv --design examples/data/design.json "
    "-o cad_out/AS_BUILT.json": 20,
    "reflector-opt optimise --conditions examples/conditions.toml -o cad_out/warm": 23,
}


def documented_commands():
    """``(page, line, command)`` of every documented command, in page order."""
    found = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for block in FENCE.finditer(text):
            start = text.count("\n", 0, block.start(3)) + 1
            lines = block.group(3).splitlines()
            for i, line in enumerate(lines):
                command = line.strip()
                if command.startswith("$ "):
                    command = command[2:]
                elif block.group(2) != "sh":
                    continue
                if not command.startswith("reflector-opt "):
                    continue
                j = i
                while command.endswith("\\"):
                    j += 1
                    command = command[:-1].rstrip() + " " + lines[j].strip()
                words = shlex.split(command, comments=True)
                found.append((page.relative_to(ROOT).as_posix(), start + i, " ".join(words)))
    return found


COMMANDS = documented_commands()


def _named_files(argv):
    """The files a command line reads: arguments, option values and ``NAME=FILE`` values that
    name a file, the value of its output option (``-o``) left out."""
    named = []
    for before, word in zip(["", *argv], argv, strict=False):
        value = word.rsplit("=", 1)[-1]
        if FILE_ARG.fullmatch(value) and before not in OUTPUT_OPTIONS:
            named.append(value)
    return named


def _parse(argv):
    """The command line's own parse (SystemExit 2 on an option it does not accept)."""
    return build_parser().parse_args(argv)


def _output(args):
    """The output file or folder the command names or defaults to, or None."""
    return getattr(args, "out", None) or getattr(args, "output", None)


def _written(argv):
    """What a command writes that a later one may name: its output file, or the design.json
    in the folder of a command that designs."""
    out = _output(_parse(argv))
    if not out:
        return set()
    return {out, f"{out.rstrip('/')}/design.json"} if argv[0] in WRITE_DESIGNS else {out}


def _producer(index, path):
    """The earlier command of the same page that writes ``path``: one run by default if any,
    else the quickest; then the nearest."""
    page = COMMANDS[index][0]
    candidates = []
    for k in range(index - 1, -1, -1):
        other_page, _, command = COMMANDS[k]
        if other_page != page or command in SKIPPED:
            continue
        if path in _written(shlex.split(command)[1:]):
            candidates.append((EXPENSIVE.get(command, 0), -k))
    return -min(candidates)[1] if candidates else None


def _workspace(index, ran, monkeypatch, name=None):
    """A scratch folder (``name``, or one for the command) with examples/ and the outputs of
    the earlier commands this one reads."""
    folder = ran["root"] / (name or f"cmd{index}")
    shutil.copytree(
        ROOT / "examples", folder / "examples", ignore=shutil.ignore_patterns("*.ipynb")
    )
    argv = shlex.split(COMMANDS[index][2])[1:]
    for path in _named_files(argv):
        if (folder / path).exists():
            continue
        k = _producer(index, path)
        assert k is not None, (
            f"{COMMANDS[index][0]}:{COMMANDS[index][1]}: {path} is neither in examples/ nor "
            "written by an earlier command of the page"
        )
        source = _run(k, ran, monkeypatch) / path
        assert source.exists(), f"{COMMANDS[k][2]} did not write {path}"
        (folder / path).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(source, folder / path)
    return folder


def _run(index, ran, monkeypatch):
    """Run command ``index`` once (its producers first); return its scratch folder."""
    command = COMMANDS[index][2]
    if command in ran["done"]:  # the same command on another page writes the same files
        return ran["done"][command]
    folder = _workspace(index, ran, monkeypatch)
    argv = shlex.split(COMMANDS[index][2])[1:]
    code, ran["printed"][command], ran["written"][command] = execute(folder, argv, monkeypatch)
    assert code == 0, f"{COMMANDS[index][0]}:{COMMANDS[index][1]}: exit {code}"
    out = _output(_parse(argv))
    if out:
        assert (folder / out).exists(), f"{COMMANDS[index][2]}: no {out} written"
    ran["done"][command] = folder
    return folder


def _stamps(folder):
    """Every file under ``folder``: its modification time and size, by relative path."""
    return {
        p.relative_to(folder).as_posix(): (p.stat().st_mtime_ns, p.stat().st_size)
        for p in folder.rglob("*")
        if p.is_file()
    }


def execute(folder, argv, monkeypatch):
    """Run ``reflector-opt argv`` quietly in ``folder``: its exit code, the text it printed
    (echoed to the test's output too) and the files it wrote (relative paths, sorted)."""
    before = _stamps(folder)
    printed = io.StringIO()
    with monkeypatch.context() as m, contextlib.redirect_stdout(printed):
        m.chdir(folder)
        code = main([*argv, "--quiet"] if "--quiet" not in argv else argv)
    sys.stdout.write(printed.getvalue())
    after = _stamps(folder)
    return code, printed.getvalue(), sorted(p for p in after if before.get(p) != after[p])


def is_slow(index):
    """Whether the test of command ``index`` takes more than about ten seconds: it runs the
    command (not one of :data:`SKIPPED`, nor of :data:`EXPENSIVE` unless those run) and that
    run is long."""
    command = COMMANDS[index][2]
    if command in SKIPPED or (command in EXPENSIVE and not RUN_ALL):
        return False
    return _runs_long(index)


def _runs_long(index):
    """Whether running command ``index`` takes more than about ten seconds: it is in
    :data:`SLOW` or :data:`EXPENSIVE`, or a command that writes what it reads does."""
    command = COMMANDS[index][2]
    if command in SLOW or command in EXPENSIVE:
        return True
    needed = [p for p in _named_files(shlex.split(command)[1:]) if not _in_examples(p)]
    return any(_runs_long(k) for k in (_producer(index, p) for p in needed) if k is not None)


def _in_examples(path):
    """Whether ``path`` is in the scratch folder's copy of examples/."""
    return path.startswith("examples/") and (ROOT / path).exists()


def command_params(indices):
    """``indices`` as test parameters, those of slow commands marked ``slow``."""
    return [pytest.param(i, marks=pytest.mark.slow) if is_slow(i) else i for i in indices]


@pytest.mark.parametrize(
    "index",
    command_params(range(len(COMMANDS))),
    ids=[f"{p.replace('/', '-')}:{n}" for p, n, _ in COMMANDS],
)
def test_documented_command_runs(index, documented_runs, monkeypatch, capsys):
    page, line, command = COMMANDS[index]
    if command in SKIPPED:
        pytest.skip(SKIPPED[command])
    for marker, module in NEEDS.items():
        if marker in command and importlib.util.find_spec(module) is None:
            pytest.skip(f"needs {module} (an optional extra)")
    argv = shlex.split(command)[1:]
    try:
        args = _parse(argv)
    except SystemExit:
        pytest.fail(f"{page}:{line}: {command}: not accepted ({capsys.readouterr().err.strip()})")
    if command in EXPENSIVE and not RUN_ALL:
        # parsed above; every file it names exists or an earlier command writes it
        for path in _named_files(argv):
            assert (ROOT / path).exists() or _producer(index, path) is not None, (
                f"{page}:{line}: {path} is neither in examples/ nor written by an earlier command"
            )
        return
    _run(index, documented_runs, monkeypatch)
    if getattr(args, "json", False):  # a --json summary is one JSON document
        json.loads(documented_runs["printed"][command])


def test_skip_and_expense_lists_name_documented_commands():
    documented = {command for _, _, command in COMMANDS}
    assert len(COMMANDS) > 40  # the pages were read
    assert set(SKIPPED) <= documented, set(SKIPPED) - documented
    assert set(EXPENSIVE) <= documented, set(EXPENSIVE) - documented


@pytest.mark.slow
def test_sample_data_is_what_the_script_writes(tmp_path):
    spec = importlib.util.spec_from_file_location(
        "make_sample_data", ROOT / "examples" / "make_sample_data.py"
    )
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    committed = ROOT / "examples" / "data"
    shutil.copy(committed / "design.json", tmp_path)
    written = script.make_sample_data(tmp_path)
    assert {p.name for p in committed.iterdir()} == {p.name for p in written} | {
        "README.md",
        "design.json",  # the optimiser's, which the script reads
        "cad.toml",  # written by hand
    }
    from tests.test_outputs_unchanged import RTOL_ITERATIVE, compare_text

    for path in written:  # built units and their calibrations: the iterative tolerance
        old, new = ((folder / path.name).read_text() for folder in (committed, path.parent))
        why = compare_text(old, new, path.name, RTOL_ITERATIVE, rounded=True)
        assert why is None, f"{path.name}: {why}"
    assert sum(p.stat().st_size for p in committed.iterdir()) < 200_000


def test_sample_log_holds_the_motion_it_says(tmp_path, capsys):
    """Calibrated on data.csv, the log gives back the paper's ±60° pitch motion the script
    recorded (each of four units ±15°, one cycle of 50 samples), not the model's own output:
    the error is the calibration's (tenths of a degree), not a perfect fit."""
    data = ROOT / "examples" / "data"
    coefficients, angles = tmp_path / "c.json", tmp_path / "a.csv"
    assert main(["calibrate", str(data / "data.csv"), "-o", str(coefficients), "-q"]) == 0
    assert (
        main(["estimate", str(coefficients), str(data / "log.csv"), "-o", str(angles), "-q"]) == 0
    )
    capsys.readouterr()
    table = np.genfromtxt(angles, delimiter=",", names=True)
    true_pitch = 15.0 * np.sin(2.0 * np.pi * np.arange(50) / 50)
    for unit in "1234":
        pitch_error = table[f"{unit}_pitch_deg"] - true_pitch
        roll_error = table[f"{unit}_roll_deg"]
        for error in (pitch_error, roll_error):
            rms = np.sqrt(np.mean(error**2))
            assert 0.02 < rms < 0.6, (unit, rms)
