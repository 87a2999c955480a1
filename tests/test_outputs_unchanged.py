"""The documented commands' outputs on the sample data hold the stored results.

Every ``reflector-opt`` command that README.md and docs/*.md show and that
``tests/test_documented_commands.py`` runs by default (not in its ``EXPENSIVE`` or ``SKIPPED``
lists, nor needing an extra the test install leaves out) runs once a session in a scratch copy
of ``examples/`` (the runs are shared with that test: the ``documented_runs`` fixture), and so
do a few of its expensive ones with a small budget option (:data:`BUDGETED`). The
text it printed and every file it wrote are compared with the golden copies in
``tests/data/golden/<command>/``, after the masks of :data:`MASKS` (wall times, dates, the
package version, the run's folder, what a library writes for itself), each with its reason.

The golden copies were made on one machine with one set of library releases; the test holds
on any machine of the project's kind and any release the dependency bounds allow, so nothing
is compared byte for byte against them (another CPU's SIMD width, fused multiply-adds, BLAS
kernels or numba's target move the last digits of a deterministic computation):

- JSON (files and ``--json`` output) is compared as a tree: the same keys, strings, booleans
  and whole numbers exactly, every other number within the tolerance of its quantity
  (:func:`tolerance`: :data:`RTOL` for a closed-form command, :data:`RTOL_ITERATIVE` for one
  whose figures come from fits and searches, and RTOL times the working size of the unit
  its key names, :data:`SCALE`); CSV the same, the quantity named by the column; other text
  (printed text, Markdown, HTML) by its words exactly and each number within the tolerance
  of the unit printed after it. A number is also accepted within
  one unit of the last digit the golden copy prints (a value on a rounding edge moves by one
  printed digit on a 1e-12 change);
- PNG figures: the size within :data:`PIXEL_SIZE_TOL` pixels a side, the mean of each of
  8 × 8 blocks within :data:`PIXEL_TOL` of full scale per channel (antialiasing and font
  hinting change single pixels, a changed colour or a moved curve moves a block);
- meshes (STL, 3MF): the same vertex and face counts, volume and area within :data:`MESH_RTOL`.

The bytes of a mesh file are a contract only on one machine (the same design and arguments
give the same STL and 3MF bytes: ``tests/cad/test_meshfiles.py`` writes them twice and
compares); they are recorded here for information, not compared.

Text larger than :data:`STORED_BYTES` is not stored: a summary is (the SHA-256 of its words,
the count, sum and sum of magnitudes of its numbers), compared with the same tolerances.

The golden copies are rewritten by
``python -m pytest tests/test_outputs_unchanged.py --regenerate-golden`` (add ``-k`` to
rewrite some). That is allowed only for an intended change of an output, and the commit that
rewrites them says which output changed and why; a refactor keeps this test passing as it is.
``.ci/run`` runs this module a second time with numpy's dispatched SIMD kernels turned off and
numba compiling for a generic CPU, as another processor of the kind would compute.
"""

from __future__ import annotations

import csv
import difflib
import hashlib
import io
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

#: What a library writes for itself, hidden in both copies before they are compared:
#: (pattern, why).
LIBRARY_MASKS = (
    (
        re.compile(r"[A-Za-z0-9+/]{64,}={0,2}"),
        "base64 in HTML: PNG bytes (matplotlib) and mesh floats (manifold3d); the PNG and mesh "
        "files are compared decoded",
    ),
    (re.compile(r"\b[0-9a-f]{64}\b"), "SHA-256 of files whose bytes the libraries write"),
    (re.compile(r"3MF \d+ kB"), "the size of a 3MF package, compressed by lib3mf and zlib"),
    (
        re.compile(r'"png_bytes": \d+'),
        "the size of a PNG file as matplotlib and zlib compress it (matplotlib 3.9 against 3.11: "
        "111858 against 112117 bytes); the figure itself is compared decoded",
    ),
)

NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")
#: The unit printed right after a number in text: "0.452°", "8.47 mm", "1 mV".
PRINTED_UNIT = re.compile(
    r" ?(°|µm|mm³|mm²|mm|mV|V|mA|A|K|%|Hz|Ω|N|model evaluations)(?![A-Za-z0-9])"
)
#: The unit a JSON key or a CSV column names by its last word: radius_mm, 1_pitch_deg, volts.
KEY_UNIT = re.compile(r"(?:^|_)(deg|um|mm3|mm2|mm|mv|v|volts|a|k|hz|ohm|n|pct)$", re.IGNORECASE)
UNIT_NAMES = {
    "deg": "°",
    "um": "µm",
    "mm3": "mm³",
    "mm2": "mm²",
    "mm": "mm",
    "mv": "mV",
    "v": "V",
    "volts": "V",
    "a": "A",
    "k": "K",
    "hz": "Hz",
    "ohm": "Ω",
    "n": "N",
    "pct": "%",
}

#: Relative tolerance of the numbers of a closed-form computation (:data:`EXACT`: meshes,
#: the model's geometry and voltages, the error budget's linear algebra). On another CPU of
#: the kind they differ only by rounding (SIMD width, fused multiply-add, BLAS and numba
#: kernels), seen at 1e-16 to 3e-13 relative; 1e-6 is a thousand times above that and ten
#: thousand times below the smallest change that is a result (a predicted error moving by
#: 1 %: 1e-2; a radius by 1 µm in 8 mm: 1.2e-4).
RTOL = 1e-6

#: Relative tolerance of the numbers of every other command: they come from iterative
#: solvers stopped by a tolerance (least-squares fits, the calibration forms' selection, the
#: optimiser's search and polish, built units calibrated in simulation). Rounding moves where
#: such a solver stops within its tolerance: a fit stopped at a relative change of cost of
#: 1e-8 has parameters known to about its square root, 1e-4 (seen with numpy's SIMD kernels
#: off: 1.3e-4 on a physical-form calibration of 25 poses in plan-calibration, 1.1e-6 on
#: fit-sensor's specular fraction and the optimiser's design). 1e-3 is ten times below a
#: predicted or calibrated error moving by 1 %.
RTOL_ITERATIVE = 1e-3

#: The commands whose outputs are closed-form computations, compared to :data:`RTOL`: no fit,
#: no search, no simulated calibration.
EXACT = (
    "reflector-opt export ",
    "reflector-opt compare examples/data/design.json --no-predict ",
    "reflector-opt evaluate examples/data/design.json --conditions examples/conditions.toml "
    "--no-predict ",
)

#: The working size of a quantity by its unit ("" for a ratio, a share or a coefficient):
#: the absolute tolerance is :data:`RTOL` times this, so that a value that is zero up to
#: rounding (a mean error, a symmetric offset, a coefficient that vanishes by symmetry) is
#: compared with the size of what it is computed from, not with itself. unit: (size, why).
SCALE = {
    "°": (1.0, "angles of ±15° to ±30° in the workspace; errors reported from 0.001°"),
    "mm": (1.0, "lengths of 0.1-25 mm; tolerances and margins from 1 µm"),
    "µm": (1e3, "the same as a length in mm"),
    "mm²": (100.0, "areas of the parts, about 100 mm²"),
    "mm³": (1e3, "volumes of the parts, about 1000 mm³"),
    "V": (1.0, "outputs of 0-3.3 V; noise and drift from 0.1 mV"),
    "mV": (1e3, "the same as a voltage in V"),
    "mA": (1.0, "LED currents of a few mA"),
    "A": (1e-6, "currents from a dark current's nA to an LED's mA"),
    "K": (1.0, "temperature ranges of 1-40 K"),
    "%": (100.0, "shares of 0-100 %"),
    "Hz": (1e3, "sample rates and flicker of 100 Hz to 100 kHz"),
    "Ω": (1e3, "resistors of 100 Ω to 100 kΩ"),
    "N": (1.0, "tendon forces of 0.1-10 N"),
    "": (
        1e-6,
        "ratios, shares and coefficients have no working size: only a value that is zero up "
        "to the last digits of double precision",
    ),
}

#: Relative tolerance of a mesh's volume and area: its vertices move by rounding
#: (manifold3d's booleans, trimesh's sums), about 1e-15 relative; a 1 µm change of the
#: reflector's radius moves its volume by about 1e-4 relative.
MESH_RTOL = 1e-6

TEXT = {".json", ".csv", ".md", ".html", ".txt", ".toml"}
IMAGE = {".png"}
MESH = {".stl", ".3mf"}
STORED_BYTES = 64_000
BLOCKS = 8
#: Largest change of an 8 × 8 block's mean pixel, as a share of full scale per channel:
#: antialiasing and font hinting move single pixels (a few 1e-4 of a block's mean, and 0.023
#: in one block of compare's difference map between matplotlib 3.9 and 3.11); a changed colour
#: or a curve moved by several line widths moves a block by more.
PIXEL_TOL = 0.03
#: Largest change of a figure's size in pixels per side: matplotlib's tight bounding box rounds
#: differently between releases (3.9 against 3.11: 505 against 506 rows).
PIXEL_SIZE_TOL = 2


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
    # its design compared, not its parts: on another processor of the kind (SIMD off) the
    # search ends a few µm apart, which moves every vertex of the meshes it writes
    "reflector-opt optimise --conditions examples/conditions.toml -o cad_out/warm": (
        ("--no-report",),
        23,
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


def library_masked(text):
    """``text`` with :data:`LIBRARY_MASKS` applied."""
    for pattern, _ in LIBRARY_MASKS:
        text = pattern.sub("<library>", text)
    return text


def words_and_numbers(text):
    """``text`` (library masks applied) split into its words, its numbers and the unit
    printed after each number."""
    text = library_masked(text)
    numbers = list(NUMBER.finditer(text))
    units = [
        (m.group(1) if (m := PRINTED_UNIT.match(text, number.end())) else "") for number in numbers
    ]
    return NUMBER.sub("#", text), [n.group() for n in numbers], units


def unit(token):
    """One unit of the last digit ``token`` prints (0 for an integer)."""
    mantissa, _, exponent = token.lower().partition("e")
    if "." not in mantissa:
        return 0.0
    decimals = len(mantissa.split(".")[1])
    return 10.0 ** (int(exponent or 0) - decimals)


def key_unit(names):
    """The unit of a quantity from the names above it (JSON keys, innermost last, or a CSV
    column): the innermost that names one (``distance_mm`` → ``"mm"``), else ``""``."""
    for name in reversed(names):
        if isinstance(name, str) and (found := KEY_UNIT.search(name)):
            return UNIT_NAMES[found.group(1).lower()]
    return ""


#: Relative tolerance of a search's count of model evaluations: an iterative search stops on
#: its tolerances, and where the last digits of a step differ (another processor's kernels)
#: its polish may take one step more (245 against 246 seen with numpy's SIMD kernels off).
EVALUATIONS_RTOL = 0.02


def number_differs(old, new, quantity, rtol=RTOL, rounded=False):
    """Why the number ``new`` (a printed token) is not ``old`` within a relative ``rtol`` and
    :data:`RTOL` times the working size of unit ``quantity`` (:data:`SCALE`), or None. Whole
    numbers (counts) are compared exactly, but for a search's evaluations
    (:data:`EVALUATIONS_RTOL`). ``rounded``: the number is printed to a fixed count of digits
    (text, not JSON or CSV, which hold every digit), so one unit of its last digit is also
    allowed."""
    if quantity in ("evaluations", "model evaluations"):
        x, y = float(old), float(new)
        if abs(x - y) > EVALUATIONS_RTOL * max(abs(x), abs(y)):
            return f"{old} became {new} (evaluations: more than {EVALUATIONS_RTOL:.0%} apart)"
        return None
    if "." not in old and "e" not in old.lower():
        return None if old == new else f"{old} became {new}"
    x, y = float(old), float(new)
    allowed = rtol * max(abs(x), abs(y)) + RTOL * SCALE[quantity][0]
    if rounded:
        allowed += unit(old) * (1 + 1e-9)
    if abs(x - y) > allowed:
        return f"{old} became {new} ({quantity or 'no unit'}: {abs(x - y):.3g} > {allowed:.3g})"
    return None


class _Number(str):
    """A number of a JSON document, kept as printed."""


def _parse_json(text):
    """A JSON text's tree with its numbers as :class:`_Number`, or None if it is not JSON
    (a mask's ``<seconds>`` read as a string)."""
    quoted = re.sub(r"\{(<[a-z0-9]+>)\}", r'"\1"', text)  # "seconds": {<seconds>}
    quoted = re.sub(r'(?<!")(<[a-z0-9]+>)(?!")', r'"\1"', quoted)
    try:
        return json.loads(quoted, parse_float=_Number, parse_int=_Number)
    except json.JSONDecodeError:
        return None


def compare_json(old, new, rtol=RTOL, path=()):
    """Why the JSON tree ``new`` differs from ``old``: keys, strings, booleans and whole
    numbers exactly, other numbers within the tolerance of the unit their keys name."""
    where = "/".join(map(str, path)) or "the document"
    if isinstance(old, _Number) and isinstance(new, _Number):
        quantity = "evaluations" if "evaluations" in path else key_unit(path)
        why = number_differs(old, new, quantity, rtol)
        return why and f"{where}: {why}"
    if type(old) is not type(new):
        return f"{where}: {old!r} became {new!r}"
    if isinstance(old, dict):
        if list(old) != list(new):
            return f"{where}: keys {list(old)} became {list(new)}"
        pairs = [((*path, key), old[key], new[key]) for key in old]
    elif isinstance(old, list):
        if len(old) != len(new):
            return f"{where}: {len(old)} items became {len(new)}"
        pairs = [((*path, i), a, b) for i, (a, b) in enumerate(zip(old, new, strict=True))]
    else:
        return None if old == new else f"{where}: {old!r} became {new!r}"
    return next((why for p, a, b in pairs if (why := compare_json(a, b, rtol, p))), None)


def compare_csv(old, new, rtol=RTOL, rounded=False):
    """Why the CSV text ``new`` differs from ``old``: the same rows and words, each number
    within the tolerance of the unit its column names (the last row of no numbers above it
    is the header); ``rounded``: the file prints its numbers to a fixed count of decimals,
    and one unit of the last is allowed (:func:`number_differs`)."""
    old_rows, new_rows = (list(csv.reader(io.StringIO(t))) for t in (old, new))
    if len(old_rows) != len(new_rows):
        return f"{len(old_rows)} rows became {len(new_rows)}"
    header = []
    for line, (a_row, b_row) in enumerate(zip(old_rows, new_rows, strict=True), 1):
        if len(a_row) != len(b_row):
            return f"row {line}: {len(a_row)} cells became {len(b_row)}"
        if not any(NUMBER.fullmatch(cell) for cell in a_row):
            header = a_row
        for column, (a, b) in enumerate(zip(a_row, b_row, strict=True)):
            name = header[column] if column < len(header) else ""
            if NUMBER.fullmatch(a) and NUMBER.fullmatch(b):
                why = number_differs(a, b, key_unit([name]), rtol, rounded)
            else:
                why = None if a == b else f"{a!r} became {b!r}"
            if why:
                return f"row {line}, {name or f'column {column + 1}'}: {why}"
    return None


def compare_prose(old, new, rtol=RTOL):
    """Why the text ``new`` differs from ``old``: the same words between the numbers, each
    number within the tolerance of the unit printed after it."""
    (old_words, old_numbers, units), (new_words, new_numbers, _) = (
        words_and_numbers(t) for t in (old, new)
    )
    if old_words != new_words or len(old_numbers) != len(new_numbers):
        diff = difflib.unified_diff(
            old_words.splitlines(), new_words.splitlines(), "golden", "now", lineterm=""
        )
        return "\n".join(list(diff)[:30]) or "a different count of numbers"
    for a, b, quantity in zip(old_numbers, new_numbers, units, strict=True):
        if why := number_differs(a, b, quantity, rtol, rounded=True):
            return why
    return None


def compare_text(old, new, name="", rtol=RTOL, rounded=False):
    """Why the text output ``new`` (file ``name``) differs from its golden copy ``old``, or
    None: as JSON, CSV or prose by what it is, numbers to a relative ``rtol`` (``rounded``:
    a CSV of numbers printed to fixed decimals)."""
    if old == new:
        return None
    old, new = library_masked(old), library_masked(new)
    if name.endswith(".csv"):
        return compare_csv(old, new, rtol, rounded)
    trees = _parse_json(old), _parse_json(new)
    if trees[0] is not None and trees[1] is not None:
        return compare_json(*trees, rtol)
    return compare_prose(old, new, rtol)


def text_summary(text):
    """A large text's fingerprint: SHA-256, its words' SHA-256, its numbers' count and sums,
    and ``slack``, the sum of one printed digit of each number."""
    words, tokens, _ = words_and_numbers(text)
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


def compare_summary(old, new, rtol=RTOL):
    """Why the summary ``new`` differs from the golden ``old``, or None."""
    if old["kind"] != new["kind"]:
        return f"was {old['kind']}, now {new['kind']}"
    if old["kind"] == "other":
        return None if old["sha256"] == new["sha256"] else "different bytes (SHA-256)"
    if old["kind"] == "mesh":
        exact = old["vertices"] == new["vertices"] and old["faces"] == new["faces"]
        close = all(
            np.isclose(old[k], new[k], rtol=MESH_RTOL, atol=0) for k in ("volume_mm3", "area_mm2")
        )
        return None if exact and close else f"mesh {old} became {new}"
    if old["kind"] == "image":
        sizes = zip(old["shape"], new["shape"], strict=True)
        if len(old["shape"]) != len(new["shape"]) or any(
            abs(a - b) > PIXEL_SIZE_TOL for a, b in sizes
        ):
            return f"image size {old['shape']} became {new['shape']}"
        worst = np.max(np.abs(np.subtract(old["block_means"], new["block_means"])))
        return None if worst <= PIXEL_TOL else f"a block of pixels changed by {worst:.3f}"
    if old["words_sha256"] != new["words_sha256"] or old["numbers"] != new["numbers"]:
        return "different words or count of numbers"
    for key in ("sum", "abs_sum"):
        # each number within rtol of itself (and of its unit's size, at most its magnitude in
        # these reports' figures) and one printed digit
        slack = max(old["slack"], new["slack"])
        if abs(old[key] - new[key]) > 2 * rtol * old["abs_sum"] + slack:
            return f"the numbers' {key} {old[key]!r} became {new[key]!r}"
    return None


def compare(old, new, name="", rtol=RTOL):
    """Why one output ``name`` differs from its golden copy (text or summary), or None."""
    if isinstance(old, str) and isinstance(new, str):
        return compare_text(old, new, name, rtol)
    old, new = (text_summary(v) if isinstance(v, str) else v for v in (old, new))
    return compare_summary(old, new, rtol)  # a text grown past STORED_BYTES or back


def tolerance(command):
    """The relative tolerance of ``command``'s numbers: :data:`RTOL` for the closed-form
    commands of :data:`EXACT`, :data:`RTOL_ITERATIVE` for the others."""
    return RTOL if f"{command} ".startswith(EXACT) else RTOL_ITERATIVE


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
    assert set(kept) == set(golden), (
        f"files written: {sorted(set(kept) - set(golden))} new, "
        f"{sorted(set(golden) - set(kept))} missing"
    )
    changed = {
        name: why
        for name in golden
        if (why := compare(golden[name], kept[name], name, tolerance(command)))
    }
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


def test_numbers_compare_to_their_printed_digits_and_their_tolerance():
    assert compare_text("d 0.720 mm", "d 0.721 mm") is None  # one printed digit
    assert compare_text("d 0.720 mm", "d 0.722 mm")
    assert compare_text("x 0.1234567890123", "x 0.1234567890124") is None
    assert compare_text("x 0.12345678901", "x 0.12345698901")  # 1.6e-6 relative
    assert compare_text("90601 poses", "90602 poses")  # a count is exact
    # but for a search's evaluations, within 2 %
    assert not compare_text("seed 0, 1146 model evaluations", "seed 0, 1147 model evaluations")
    assert compare_text("seed 0, 1146 model evaluations", "seed 0, 1200 model evaluations")
    old, new = '{"evaluations": {"polish": 245}}', '{"evaluations": {"polish": 246}}'
    assert not compare_text(old, new, "design.json")
    assert compare_text(old, '{"evaluations": {"polish": 260}}', "design.json")
    assert compare_text("in range", "out of range")
    assert compare_text('{"e_deg": 0.0}', '{"e_deg": 3e-17}') is None  # zero up to rounding
    assert compare_text('{"e_deg": 0.0}', '{"e_deg": 3e-6}')  # past the angle's atol
    assert compare_text('{"e": 0.0}', '{"e": 3e-11}')  # no unit: no atol to speak of


def _golden(command_start):
    """The first compared command starting with ``command_start``: its golden outputs and
    the relative tolerance of its numbers."""
    command = next(c for _, c in GOLDEN_COMMANDS if c.startswith(command_start))
    return read_golden(command)[1], tolerance(command)


def _moved(text, key, factor):
    """``text`` (JSON) with the first number under ``"key":`` multiplied by ``factor``."""
    match = re.search(rf'"{key}": ({NUMBER.pattern})', text)
    moved = repr(float(match.group(1)) * factor)
    return text[: match.start(1)] + moved + text[match.end(1) :]


def test_each_command_has_the_tolerance_of_what_computes_its_figures():
    assert tolerance("reflector-opt export examples/data/design.json") == RTOL
    assert tolerance("reflector-opt calibrate examples/data/data.csv --model auto") == (
        RTOL_ITERATIVE
    )
    assert tolerance("reflector-opt optimise --conditions examples/conditions.toml") == (
        RTOL_ITERATIVE
    )
    assert sum(tolerance(c) == RTOL for _, c in GOLDEN_COMMANDS) == 6  # every EXACT runs


@pytest.mark.parametrize(
    ("key", "factor", "fails"),
    [
        ("worst_pitch_deg", 1.01, True),  # a predicted error +1 %
        ("worst_pitch_deg", 0.99, True),
        ("worst_pitch_deg", 1.0005, False),  # half the iterative tolerance
        ("worst_pitch_deg", 1.002, True),  # twice it
        ("worst_pitch_deg", 1 + 3e-13, False),  # what another CPU was seen to change
        ("min", 1.01, True),  # a voltage (the key names no unit, "volts" above it does)
    ],
)
def test_a_key_figure_moved_past_its_tolerance_fails(key, factor, fails):
    """evaluate --json's golden output (its predictions are simulated calibrations: the
    iterative tolerance) against itself with one figure moved."""
    golden, rtol = _golden("reflector-opt evaluate examples/data/design.json --json")
    text = golden["<printed>"]
    why = compare(text, _moved(text, key, factor), "<printed>", rtol)
    assert bool(why) is fails, why
    if fails:
        assert key in why


def test_a_closed_form_figure_moved_past_its_tolerance_fails():
    """The error budget of evaluate --conditions --no-predict (closed form, RTOL): a term
    moved by ten times RTOL fails, by a tenth of it passes."""
    golden, rtol = _golden("reflector-opt evaluate examples/data/design.json --conditions")
    assert rtol == RTOL
    text = golden["<printed>"]
    key = "worst_case_deg"  # the budget's worst case, 1.1°
    assert compare(text, _moved(text, key, 1 + 10 * RTOL), "<printed>", rtol)
    assert compare(text, _moved(text, key, 1 + RTOL / 10), "<printed>", rtol) is None


def test_a_calibration_error_moved_by_one_percent_fails():
    """calibrate's coefficients file: a cross-validated error +1 % is a changed output. Its
    printed table holds three decimals, so there a change shows from two printed digits (a
    1 % change of 0.119° is one, which a value on a rounding edge also makes)."""
    golden, rtol = _golden("reflector-opt calibrate examples/data/data.csv --model auto")
    name = next(n for n in golden if n.endswith("coefficients.json"))
    key = "pitch_deg"  # the first: unit 1's cross-validated RMS pitch error
    assert '"rms_deg": {\n          "pitch_deg"' in golden[name]
    assert compare(golden[name], _moved(golden[name], key, 1.01), name, rtol)
    assert compare(golden[name], _moved(golden[name], key, 1 + rtol / 10), name, rtol) is None
    printed = golden["<printed>"]
    first = re.search(r"(\d+\.\d{3})°", printed)
    for step, fails in ((0.001, False), (0.002, True)):
        moved = f"{float(first.group(1)) + step:.3f}"
        changed = printed[: first.start(1)] + moved + printed[first.end(1) :]
        assert bool(compare(printed, changed, "<printed>", rtol)) is fails


def test_csv_numbers_take_their_column_s_unit():
    old = "pose,pitch_deg,yield\n1,0.0,0.5\n"
    assert compare_text(old, "pose,pitch_deg,yield\n1,5e-7,0.5\n", "a.csv") is None
    assert compare_text(old, "pose,pitch_deg,yield\n1,5e-6,0.5\n", "a.csv")
    assert compare_text(old, "pose,pitch_deg,yield\n1,0.0,0.5000001\n", "a.csv") is None
    assert compare_text(old, "pose,pitch_deg,yield\n1,0.0,0.50001\n", "a.csv")
    assert compare_text(old, "pose,pitch_deg,yield\n2,0.0,0.5\n", "a.csv")  # a count
    assert compare_text(old, "pose,roll_deg,yield\n1,0.0,0.5\n", "a.csv")  # a word


def test_json_structure_is_compared_exactly():
    old = '{"a_mm": 1.0, "ok": true, "name": "S1", "n": 3}'
    assert compare_text(old, '{"a_mm": 1.0000001, "ok": true, "name": "S1", "n": 3}') is None
    assert compare_text(old, '{"a_mm": 1.0, "ok": false, "name": "S1", "n": 3}')
    assert compare_text(old, '{"a_mm": 1.0, "ok": true, "name": "S2", "n": 3}')
    assert compare_text(old, '{"a_mm": 1.0, "ok": true, "name": "S1", "n": 4}')
    assert compare_text(old, '{"ok": true, "a_mm": 1.0, "name": "S1", "n": 3}')  # key order
    assert compare_text('{"s": <seconds>, "x_mm": 2.0}', '{"s": <seconds>, "x_mm": 2.1}')


def test_meshes_and_images_compare_by_their_meaning():
    mesh = {
        "kind": "mesh",
        "sha256": "a",
        "vertices": 8,
        "faces": 12,
        "volume_mm3": 1000.0,
        "area_mm2": 600.0,
    }
    assert compare_summary(mesh, {**mesh, "sha256": "b"}) is None  # bytes are not the contract
    assert compare_summary(mesh, {**mesh, "volume_mm3": 1000.0 * (1 + MESH_RTOL / 2)}) is None
    assert compare_summary(mesh, {**mesh, "volume_mm3": 1000.1})
    assert compare_summary(mesh, {**mesh, "faces": 14})
    image = {"kind": "image", "sha256": "a", "shape": [500, 800, 4], "block_means": [[0.5, 0.5]]}
    assert compare_summary(image, {**image, "sha256": "b", "block_means": [[0.52, 0.5]]}) is None
    assert compare_summary(image, {**image, "block_means": [[0.54, 0.5]]})
    assert compare_summary(image, {**image, "shape": [499, 800, 4]}) is None  # a rounded row
    assert compare_summary(image, {**image, "shape": [490, 800, 4]})
