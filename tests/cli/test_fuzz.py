"""Random and mutated input files give a clean error or a correct result, for every reader.

Each reader of the command line — the optimise and tolerance configs, the CAD parameters
(TOML), the coefficients (JSON), the calibration CSV, the voltage log and the sensor curve
(CSV) — gets valid files with random edits: spans deleted, and tokens inserted that break
syntax, types and ranges (NaN, infinities, numbers beyond the float range, quotes, brackets,
control characters, a byte-order mark). Whatever the file, reading it returns a value whose
numbers are all finite, or raises an :class:`~reflector_opt.util._errors.InputError` of one
line naming the
file; any other exception (a warning included: warnings are errors in the tests) is a bug.
Bytes that are not UTF-8 text are refused. A voltage log that reads is also
estimated, streamed or whole, to the same numbers as the in-memory path.
"""

import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from reflector_opt.calibration._files import (
    read_calibration_csv,
)
from reflector_opt.calibration._unit_calibration import (
    estimate_log,
    estimate_to_csv,
    load_calibrations,
)
from reflector_opt.cli import main
from reflector_opt.design._parts import CadParameters, load_cad_parameters
from reflector_opt.model._measured import read_curve_csv
from reflector_opt.optimiser._config import load_config
from reflector_opt.tolerance._config import load_tolerance_config
from reflector_opt.util._errors import InputError
from tests.labfiles import write_lab_files
from tests.mutation import finite_values

ROOT = Path(__file__).resolve().parents[2]

TOKENS = (
    "",
    "0",
    "-1",
    "2.5",
    "1e999",
    "1e308",
    "-1e308",
    "9" * 400,
    "nan",
    "inf",
    "NaN",
    "Infinity",
    "true",
    "null",
    '"',
    "'",
    ",",
    "\n",
    "=",
    "[",
    "]",
    "{",
    "}",
    '"x"',
    "\x00",
    "\ufeff",
    "é",
    "[[",
    "# ",
)


@st.composite
def mutated(draw, text):
    """``text`` with up to four random edits."""
    for _ in range(draw(st.integers(1, 4))):
        at = draw(st.integers(0, len(text)))
        if draw(st.booleans()):
            end = min(len(text), at + draw(st.integers(1, 12)))
            text = text[:at] + text[end:]
        else:
            text = text[:at] + draw(st.sampled_from(TOKENS)) + text[at:]
    return text


@pytest.fixture(scope="module")
def valid(tmp_path_factory):
    """One valid file for each reader, and the coefficients of the simulated units."""
    folder = tmp_path_factory.mktemp("valid")
    write_lab_files(folder)
    fields = dataclasses.asdict(CadParameters())
    (folder / "cad.toml").write_text(
        "[cad]\n" + "".join(f"{k} = {v!r}\n" for k, v in fields.items() if v is not None)
    )
    d = np.linspace(0.4, 3.4, 8)
    (folder / "curve.csv").write_text(
        "distance_mm,volts\n" + "".join(f"{a},{2.5 - 0.5 * a}\n" for a in d)
    )
    shutil.copy(ROOT / "examples" / "optimise.toml", folder / "optimise.toml")
    shutil.copy(ROOT / "examples" / "tolerance.toml", folder / "tolerance.toml")
    return folder


READERS = {
    "optimise.toml": load_config,
    "tolerance.toml": load_tolerance_config,
    "cad.toml": load_cad_parameters,
    "coef.json": load_calibrations,
    "data.csv": read_calibration_csv,
    "curve.csv": read_curve_csv,
}


def _read_or_refused(name, path):
    """The reader's contract on any file: refused by an InputError of one line that names the
    file, or read to a result of every number finite. Any other exception propagates."""
    try:
        result = READERS[name](path)
    except InputError as exc:
        message = str(exc)
        assert message and "\n" not in message.strip(), message
        assert path.name in message, message
        return None
    finite_values(result)
    return result


@pytest.mark.parametrize("name", READERS)
def test_valid_files_read(valid, name):
    assert _read_or_refused(name, valid / name) is not None


@pytest.mark.parametrize("name", READERS)
@settings(
    max_examples=60,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_a_mutated_file_reads_or_is_an_input_error(valid, tmp_path, name, data):
    text = data.draw(mutated((valid / name).read_text(encoding="utf-8")))
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    _read_or_refused(name, path)


@settings(
    max_examples=80,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_a_mutated_log_is_estimated_correctly_or_is_an_input_error(valid, tmp_path, data):
    text = data.draw(mutated((valid / "log.csv").read_text(encoding="utf-8")))
    log, output = tmp_path / "log.csv", tmp_path / "angles.csv"
    log.write_text(text, encoding="utf-8")
    output.unlink(missing_ok=True)
    calibrations = load_calibrations(valid / "coef.json")
    try:
        done = estimate_to_csv(calibrations, log, output)
    except InputError as exc:
        assert "\n" not in str(exc).strip() and not output.exists()
        with pytest.raises(InputError):
            estimate_log(calibrations, log)
        return
    shape = estimate_log(calibrations, log)
    assert done["instants"] == len(shape.instants)
    rows = [line.split(",") for line in output.read_text(encoding="utf-8").splitlines()[1:]]
    np.testing.assert_array_equal(
        np.array([[float(x) for x in r[1:]] for r in rows]), shape.table()
    )


@settings(max_examples=40, deadline=None)
@given(blob=st.binary(max_size=300))
def test_random_bytes_are_refused_unless_they_are_a_valid_text_file(tmp_path_factory, blob):
    """Bytes that are not UTF-8 text are refused by every reader; text is refused or read to
    finite values. A file read to a result must hold what the reader needs: the CSV readers'
    header, the data's voltage columns."""
    folder = tmp_path_factory.mktemp("bytes")
    try:
        text = blob.decode("utf-8")
    except UnicodeDecodeError:
        text = None
    for name in READERS:
        path = folder / name
        path.write_bytes(blob)
        result = _read_or_refused(name, path)
        if result is not None:
            assert text is not None, name
            if name.endswith(".csv"):
                assert "distance_mm" in text or "v1" in text, (name, text)


@settings(
    max_examples=40,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data(), target=st.sampled_from(["coef.json", "log.csv"]))
def test_the_command_line_on_mutated_files_succeeds_or_says_one_line(
    valid, tmp_path, capsys, data, target
):
    files = {name: tmp_path / name for name in ("coef.json", "log.csv")}
    for name, path in files.items():
        text = (valid / name).read_text(encoding="utf-8")
        path.write_text(data.draw(mutated(text)) if name == target else text, encoding="utf-8")
    output = tmp_path / "angles.csv"
    output.unlink(missing_ok=True)
    code = main(["estimate", str(files["coef.json"]), str(files["log.csv"]), "-o", str(output)])
    out, err = capsys.readouterr()
    if code == 0:
        assert output.is_file() and "wrote" in out and err == ""
    else:
        assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
        assert err.startswith("reflector-opt estimate: error: ") and not output.exists()
