"""The documented commands' outputs on the sample data are the stored ones, byte for byte.

Every ``reflector-opt`` command that README.md and docs/*.md show and that
``tests/test_documented_commands.py`` runs by default (not in its ``EXPENSIVE`` or ``SKIPPED``
lists, nor needing an extra the test install leaves out) runs once a session in a scratch copy
of ``examples/`` (the runs are shared with that test: the ``documented_runs`` fixture), and so
do a few of its expensive ones with a small budget option (:data:`BUDGETED`). The
text it printed and every file it wrote are compared with the golden copies in
``tests/data/golden/<command>/``, after the masks of :data:`MASKS` (wall times, dates, the
package version, the run's folder), each with its reason.

How the comparison depends on the installed libraries. Each golden folder records the
versions of the libraries that made it (:data:`LIBRARIES`, the Python version and the
machine). With the same versions:

- text (JSON, CSV, Markdown, HTML, printed text) is compared byte for byte after the masks;
- PNG figures and meshes (STL, 3MF) by their SHA-256.

With any of them different (CI installs the newest releases in a fresh venv), a dependency's
release alone must not fail the test, a changed result must:

- text: the words between the numbers must be the same, and every number equal to a relative
  1e-9, or within one unit of the last digit the golden copy prints (a value on a rounding
  edge moves by one printed digit on a 1e-12 change); :data:`FALLBACK_MASKS` also hides what
  a library writes for itself (base64 of PNG pixels and mesh floats in HTML, zip sizes);
- PNG figures: the same size, and the mean of each of 8 × 8 blocks of pixels within 0.02 of
  full scale per channel (antialiasing and font hinting change single pixels, a moved curve
  or a changed colour moves a block);
- meshes: the same vertex and face counts, and volume and area to a relative 1e-9.

Text larger than :data:`STORED_BYTES` is not stored: its SHA-256 (after the masks) and a
summary (the SHA-256 of its words, the count, sum and sum of magnitudes of its numbers) are,
and the summary is what is compared when the versions differ.

The golden copies are rewritten by
``python -m pytest tests/test_outputs_unchanged.py --regenerate-golden`` (add ``-k`` to
rewrite some). That is allowed only for an intended change of an output, and the commit that
rewrites them says which output changed and why; a refactor keeps this test passing as it is.
"""

from __future__ import annotations

import difflib
import hashlib
import json
import platform
import re
import shlex
import shutil
import sys
from importlib import metadata
from pathlib import Path

import numpy as np
import pytest

from tests.test_documented_commands import (
    COMMANDS,
    EXPENSIVE,
    NEEDS,
    ROOT,
    SKIPPED,
    _run,
    _workspace,
    execute,
    is_slow,
)

GOLDEN = ROOT / "tests" / "data" / "golden"

#: The libraries whose releases may change an output's bytes without changing the result:
#: the numerics (numpy, scipy, numba, cvxpy), the meshes (manifold3d, trimesh, lib3mf, coal),
#: the figures (matplotlib, pillow) and the tables and templates (pyarrow, jinja2).
LIBRARIES = (
    "numpy",
    "scipy",
    "numba",
    "llvmlite",
    "cvxpy",
    "manifold3d",
    "trimesh",
    "lib3mf",
    "coal",
    "matplotlib",
    "pillow",
    "pyarrow",
    "jinja2",
)

#: Masks on every text output and printed text: (pattern, replacement, why).
MASKS = (
    (
        re.compile(r"((?:wrote \d+ files?|identified) in )\d+(?:\.\d+)? s\b"),
        r"\1<seconds> s",
        "the run's wall time, printed",
    ),
    (
        re.compile(r"(nothing written \()\d+(?:\.\d+)? s\)"),
        r"\1<seconds> s)",
        "the run's wall time, printed when it wrote nothing",
    ),
    (
        re.compile(r'("file": "[^"]*",\s*"sha256": )"[0-9a-f]{64}"'),
        r'\1"<sha256>"',
        "the hash of an input file as read, where that file records a wall time (the "
        "AS_BUILT.json a corrected design.json names); the input is compared where it is written",
    ),
    (
        re.compile(r'("seconds": )-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?'),
        r"\1<seconds>",
        "a wall time recorded in a file (identify's AS_BUILT.json)",
    ),
    (
        re.compile(r'("seconds": \{)[^{}]*(\})'),
        r"\1<seconds>\2",
        "the wall times of the search's stages recorded in design.json",
    ),
    (re.compile(r'("created": )"[^"]*"'), r'\1"<date>"', "the date and time in manifest.json"),
    (
        re.compile(r'("bytes": )\d+(,\s*"sha256": )"[0-9a-f]{64}"'),
        r'\1<bytes>\2"<sha256>"',
        "manifest.json's sizes and hashes of the files as written (wall times and dates "
        "included); each of those files is compared itself",
    ),
)

#: Masks added when the libraries' versions differ from the golden copy's: (pattern, why).
FALLBACK_MASKS = (
    (
        re.compile(r"[A-Za-z0-9+/]{64,}={0,2}"),
        "base64 in HTML: PNG bytes (matplotlib) and mesh floats (manifold3d); the PNG and mesh "
        "files are compared decoded",
    ),
    (re.compile(r"\b[0-9a-f]{64}\b"), "SHA-256 of files whose bytes the libraries write"),
    (re.compile(r"3MF \d+ kB"), "the size of a 3MF package, compressed by lib3mf and zlib"),
)

NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")
TEXT = {".json", ".csv", ".md", ".html", ".txt", ".toml"}
IMAGE = {".png"}
MESH = {".stl", ".3mf"}
STORED_BYTES = 64_000
RTOL = 1e-9
BLOCKS = 8
PIXEL_TOL = 0.02


#: Documented commands that ``tests/test_documented_commands.py`` only parses (its
#: ``EXPENSIVE``), compared here with a small budget: the options added to the documented line
#: (none where the line itself is quick), and the seconds one run took on 2 cores.
BUDGETED = {
    "reflector-opt sweep examples/data/design.json --vary reflector.radius_mm=8.35:8.55:5 "
    "--samples 50": ((), 5),
    "reflector-opt plan-calibration examples/data/design.json -o cad_out/plan": (
        ("--units", "1"),
        13,
    ),
}


def golden_commands():
    """``(index, command line)`` of each compared command, first occurrence: the documented
    ones run by default, then :data:`BUDGETED` with their options."""
    chosen, seen = [], set()
    for index, (_, _, command) in enumerate(COMMANDS):
        if command in seen or command in SKIPPED or any(mark in command for mark in NEEDS):
            continue
        seen.add(command)
        if command in BUDGETED:
            chosen.append((index, " ".join([command, *BUDGETED[command][0]])))
        elif command not in EXPENSIVE:
            chosen.append((index, command))
    return chosen


def _params():
    """The compared commands as test parameters, slow ones marked."""
    slow = {i for i in range(len(COMMANDS)) if is_slow(i)}
    slow |= {i for i, line in GOLDEN_COMMANDS if BUDGETED.get(COMMANDS[i][2], ((), 0))[1] > 10}
    return [
        pytest.param(case, marks=pytest.mark.slow) if case[0] in slow else case
        for case in GOLDEN_COMMANDS
    ]


def _ran(index, line, runs, monkeypatch):
    """Run the compared command line once a session (a documented one through the shared
    runs, a budgeted one in a folder of its own); its key in ``runs``."""
    if line == COMMANDS[index][2]:
        _run(index, runs, monkeypatch)
    elif line not in runs["done"]:
        folder = _workspace(index, runs, monkeypatch, name=slug(line))
        code, runs["printed"][line], runs["written"][line] = execute(
            folder, shlex.split(line)[1:], monkeypatch
        )
        assert code == 0, f"{line}: exit {code}"
        runs["done"][line] = folder
    return line


def slug(command):
    """The golden folder's name of a command line: its words after ``reflector-opt``."""
    words = shlex.split(command)[1:]
    name = re.sub(r"[^A-Za-z0-9._=-]+", "-", "_".join(words)).strip("-")
    if len(name) > 72:
        name = f"{name[:60]}-{hashlib.sha1(command.encode()).hexdigest()[:8]}"
    return name


def versions():
    """The versions of :data:`LIBRARIES`, Python's and the machine's."""
    found = {name: metadata.version(name) for name in LIBRARIES}
    found["python"] = ".".join(platform.python_version_tuple()[:2])
    found["machine"] = platform.machine()
    return found


def mask(text, folder):
    """``text`` with :data:`MASKS` applied and the run's folder, the repository and the
    environment's prefix written as ``<run>``, ``<root>``, ``<prefix>`` (absolute paths)."""
    for path, name in ((folder, "<run>"), (ROOT, "<root>"), (Path(sys.prefix), "<prefix>")):
        text = text.replace(str(path), name)
    text = re.sub(
        rf'("version": )"{re.escape(metadata.version("reflector-opt"))}"',
        r'\1"<version>"',
        text,
    )  # the package's version in manifest.json: a release, not a result
    for pattern, replacement, _ in MASKS:
        text = pattern.sub(replacement, text)
    return text


def fallback(text):
    """``text`` with :data:`FALLBACK_MASKS`, split into its words and its numbers."""
    for pattern, _ in FALLBACK_MASKS:
        text = pattern.sub("<library>", text)
    return NUMBER.sub("#", text), NUMBER.findall(text)


def unit(token):
    """One unit of the last digit ``token`` prints (0 for an integer)."""
    mantissa, _, exponent = token.lower().partition("e")
    if "." not in mantissa:
        return 0.0
    decimals = len(mantissa.split(".")[1])
    return 10.0 ** (int(exponent or 0) - decimals)


def text_summary(text):
    """A large text's fingerprint: SHA-256, its words' SHA-256, its numbers' count and sums."""
    words, tokens = fallback(text)
    values = np.array([float(t) for t in tokens])
    return {
        "kind": "text-digest",
        "sha256": hashlib.sha256(text.encode()).hexdigest(),
        "words_sha256": hashlib.sha256(words.encode()).hexdigest(),
        "numbers": len(tokens),
        "sum": float(values.sum()),
        "abs_sum": float(np.abs(values).sum()),
        "slack": float(sum(unit(t) for t in tokens)),
    }


def image_summary(path):
    """A PNG's SHA-256, size and the mean of each of 8 × 8 pixel blocks per channel."""
    from matplotlib.image import imread

    pixels = imread(path)
    rows = np.array_split(np.arange(pixels.shape[0]), BLOCKS)
    cols = np.array_split(np.arange(pixels.shape[1]), BLOCKS)
    means = [[pixels[np.ix_(r, c)].mean(axis=(0, 1)).round(4).tolist() for c in cols] for r in rows]
    return {
        "kind": "image",
        "sha256": hashlib.sha256(path.read_bytes()).hexdigest(),
        "shape": list(pixels.shape),
        "block_means": means,
    }


def mesh_summary(path):
    """A mesh file's SHA-256, vertex and face counts, volume (mm³) and area (mm²)."""
    import trimesh

    mesh = trimesh.load(path, force="mesh")
    return {
        "kind": "mesh",
        "sha256": hashlib.sha256(path.read_bytes()).hexdigest(),
        "vertices": len(mesh.vertices),
        "faces": len(mesh.faces),
        "volume_mm3": float(mesh.volume),
        "area_mm2": float(mesh.area),
    }


def record(path, folder):
    """What is kept of one written file: its masked text, or a summary (``dict``)."""
    suffix = path.suffix.lower()
    if suffix in TEXT:
        text = mask(path.read_text(encoding="utf-8"), folder)
        return text if len(text.encode()) <= STORED_BYTES else text_summary(text)
    if suffix in IMAGE:
        return image_summary(path)
    if suffix in MESH:
        return mesh_summary(path)
    return {"kind": "other", "sha256": hashlib.sha256(path.read_bytes()).hexdigest()}


def _numbers_differ(old, new):
    """The first pair of numbers that differ beyond :data:`RTOL` and one printed unit."""
    for a, b in zip(old, new, strict=True):
        x, y = float(a), float(b)
        if abs(x - y) > RTOL * max(abs(x), abs(y)) + unit(a) * (1 + 1e-9):
            return f"{a} became {b}"
    return None


def compare_text(old, new, same_versions):
    """Why ``new`` text differs from the golden ``old``, or None."""
    if old == new:
        return None
    if same_versions:
        diff = difflib.unified_diff(
            old.splitlines(), new.splitlines(), "golden", "now", lineterm=""
        )
        return "\n".join(list(diff)[:30])
    (old_words, old_numbers), (new_words, new_numbers) = fallback(old), fallback(new)
    if old_words != new_words or len(old_numbers) != len(new_numbers):
        return compare_text(old_words, new_words, True) or "a different count of numbers"
    return _numbers_differ(old_numbers, new_numbers)


def compare_summary(old, new, same_versions):
    """Why the summary ``new`` differs from the golden ``old``, or None."""
    if old["kind"] != new["kind"]:
        return f"was {old['kind']}, now {new['kind']}"
    if same_versions or old["kind"] == "other":
        return None if old["sha256"] == new["sha256"] else "different bytes (SHA-256)"
    if old["kind"] == "mesh":
        exact = old["vertices"] == new["vertices"] and old["faces"] == new["faces"]
        close = all(
            np.isclose(old[k], new[k], rtol=RTOL, atol=0) for k in ("volume_mm3", "area_mm2")
        )
        return None if exact and close else f"mesh {old} became {new}"
    if old["kind"] == "image":
        if old["shape"] != new["shape"]:
            return f"image size {old['shape']} became {new['shape']}"
        worst = np.max(np.abs(np.subtract(old["block_means"], new["block_means"])))
        return None if worst <= PIXEL_TOL else f"a block of pixels changed by {worst:.3f}"
    if old["words_sha256"] != new["words_sha256"] or old["numbers"] != new["numbers"]:
        return "different words or count of numbers"
    for key in ("sum", "abs_sum"):
        if abs(old[key] - new[key]) > RTOL * old["abs_sum"] + old["slack"]:
            return f"the numbers' {key} {old[key]!r} became {new[key]!r}"
    return None


def compare(old, new, same_versions):
    """Why one output differs from its golden copy (text or summary), or None."""
    if isinstance(old, str) and isinstance(new, str):
        return compare_text(old, new, same_versions)
    old, new = (text_summary(v) if isinstance(v, str) else v for v in (old, new))
    return compare_summary(old, new, same_versions)  # a text grown past STORED_BYTES or back


def outputs(command, runs):
    """The printed text and the written files of a run, as :func:`record` keeps them."""
    folder = runs["done"][command]
    kept = {"<printed>": mask(runs["printed"][command], folder)}
    for relative in runs["written"][command]:
        kept[relative] = record(folder / relative, folder)
    return kept


def write_golden(command, kept):
    """Replace the golden folder of ``command`` with ``kept``."""
    target = GOLDEN / slug(command)
    shutil.rmtree(target, ignore_errors=True)
    summaries = {}
    for relative, value in kept.items():
        if isinstance(value, str):
            path = target / ("printed.txt" if relative == "<printed>" else f"files/{relative}")
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(value, encoding="utf-8")
            value = {"kind": "text"}
        summaries[relative] = value
    index = {"command": command, "versions": versions(), "outputs": summaries}
    (target / "summary.json").write_text(json.dumps(index, indent=1) + "\n", encoding="utf-8")


def read_golden(command):
    """The golden copy of ``command``: (its versions, its outputs as :func:`outputs` gives)."""
    target = GOLDEN / slug(command)
    if not (target / "summary.json").exists():
        pytest.fail(f"no golden copy of {command!r} in {target}; see this module's docstring")
    index = json.loads((target / "summary.json").read_text(encoding="utf-8"))
    kept = {}
    for relative, value in index["outputs"].items():
        if value["kind"] == "text":
            path = target / ("printed.txt" if relative == "<printed>" else f"files/{relative}")
            value = path.read_text(encoding="utf-8")
        kept[relative] = value
    return index["versions"], kept


GOLDEN_COMMANDS = golden_commands()


@pytest.mark.parametrize("case", _params(), ids=[slug(c) for _, c in GOLDEN_COMMANDS])
def test_outputs_are_the_golden_copies(case, documented_runs, monkeypatch, request):
    command = _ran(*case, documented_runs, monkeypatch)
    kept = outputs(command, documented_runs)
    if request.config.getoption("--regenerate-golden"):
        write_golden(command, kept)
        return
    golden_versions, golden = read_golden(command)
    now = versions()
    same = golden_versions == now
    assert set(kept) == set(golden), (
        f"files written: {sorted(set(kept) - set(golden))} new, "
        f"{sorted(set(golden) - set(kept))} missing"
    )
    changed = {name: why for name in golden if (why := compare(golden[name], kept[name], same))}
    differing = {k: (v, now[k]) for k, v in golden_versions.items() if now.get(k) != v}
    assert not changed, "\n".join(
        [f"{command}: outputs changed (library versions differing: {differing or 'none'})"]
        + [f"--- {name}: {why}" for name, why in changed.items()]
    )


def test_golden_folders_are_the_documented_commands():
    """A golden folder of a command no longer documented is stale (delete it); two commands
    may not share one."""
    names = [slug(c) for _, c in GOLDEN_COMMANDS]
    assert len(set(names)) == len(names)
    stored = {p.name for p in GOLDEN.iterdir() if p.is_dir()} if GOLDEN.exists() else set()
    assert stored <= set(names), sorted(stored - set(names))


def test_masks_hide_what_they_say_and_nothing_else(tmp_path):
    wall = 'wrote 3 files in 12.5 s:\n  "seconds": 52.67,\n "seconds": {"search": 2.8}'
    wall += "\n4 unit(s) identified in 14.5 s\nnothing written (0.47 s)"
    stamp = '"created": "2026-11-26T22:01:22+00:00", "bytes": 12,\n "sha256": "' + "a" * 64 + '"'
    masked = mask(f"{wall}\n{stamp}\n{tmp_path}/x.json", tmp_path)
    assert not re.search(r"12\.5|52\.67|2\.8|14\.5|0\.47|2026|\b12\b|aaaa", masked), masked
    assert "<run>/x.json" in masked
    kept = 'radius 8.474 mm, "radius_mm": 8.47412345, in 3 s'
    assert mask(kept, tmp_path) == kept


def test_numbers_compare_to_their_printed_digits_when_versions_differ():
    assert compare_text("d 0.720 mm", "d 0.721 mm", same_versions=False) is None
    assert compare_text("d 0.720 mm", "d 0.722 mm", same_versions=False)
    assert compare_text("x 0.1234567890123", "x 0.1234567890124", same_versions=False) is None
    assert compare_text("x 0.12345678901", "x 0.12345679901", same_versions=False)
    assert compare_text("90601 poses", "90602 poses", same_versions=False)
    assert compare_text("d 0.720 mm", "d 0.721 mm", same_versions=True)
    assert compare_text("in range", "out of range", same_versions=False)
