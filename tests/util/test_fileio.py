"""The shared readers and writers: every failure one InputError naming the file."""

import json
import math
import os

import pytest

from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import (
    MAX_DEPTH,
    MAX_DOCUMENT_BYTES,
    MAX_LINE_CHARS,
    atomic_path,
    read_config,
    read_csv,
    read_json,
    read_text,
    read_toml,
    write_json,
    write_text,
)


def _file(tmp_path, text, name="input.json"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_read_json_gives_plain_values(tmp_path):
    data = {"a": [1, 2.5, None, True, "x"], "b": {"c": -3}}
    assert read_json(_file(tmp_path, json.dumps(data))) == data


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('{"a": 1, "b": {"c": 1, "c": 2}}', "the key 'c' appears twice in one object"),
        ("[" * 100_000 + "]" * 100_000, f"nested more than {MAX_DEPTH} levels deep"),
        ("[" * (MAX_DEPTH + 2) + "]" * (MAX_DEPTH + 2), f"nested more than {MAX_DEPTH} levels"),
        ('{"n": ' + "1" + "0" * 309 + "}", "n: the number is too large"),
        ('{"n": [0, -' + "9" * 5000 + "]}", "n[1]: the number is too large"),
        ('{"n": [1, 2e400]}', "n[1]: got inf; numbers must be finite"),
        ('{"n": {"m": NaN}}', "n.m: got nan"),
        ('{"n": -Infinity}', "n: got -inf"),
        ('{"n": 1,}', "not valid JSON"),
    ],
)
def test_read_json_refuses_hostile_documents(tmp_path, text, message):
    path = _file(tmp_path, text)
    with pytest.raises(InputError, match=r"^" + str(path)) as exc:
        read_json(path)
    assert message in str(exc.value)


def test_read_json_keeps_large_finite_numbers(tmp_path):
    big = "9" * 300
    assert read_json(_file(tmp_path, f"[{big}, 1e300]")) == [int(big), 1e300]


def test_unreadable_files_are_input_errors(tmp_path):
    with pytest.raises(InputError, match="cannot read"):
        read_json(tmp_path)
    with pytest.raises(InputError, match="cannot read"):
        read_json(tmp_path / "missing.json")
    binary = tmp_path / "binary.json"
    binary.write_bytes(b"\xff\x00\xfe")
    with pytest.raises(InputError, match="not a UTF-8 text file"):
        read_json(binary)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("a = 1\na = 2\n", "not valid TOML"),
        ("a = 1" + "0" * 400 + "\n", "a: the number is too large"),
        ("a = 1" + "0" * 5000 + "\n", "a number is too large"),
        ("[t]\nb = [1, nan]\n", "t.b[1]: got nan"),
        ("b = inf\n", "b: got inf"),
        ("a = " + "[" * 3000 + "]" * 3000 + "\n", "nested more than"),
    ],
)
def test_read_toml_refuses_hostile_documents(tmp_path, text, message):
    path = _file(tmp_path, text, "config.toml")
    with pytest.raises(InputError, match=r"^" + str(path)) as exc:
        read_toml(path)
    assert message in str(exc.value)


def test_read_csv_gives_lines_and_cells(tmp_path):
    path = _file(tmp_path, "\ufeffa,b\n\n1,2\n , \n3,4\n", "t.csv")
    assert read_csv(path) == [(1, ["a", "b"]), (3, ["1", "2"]), (5, ["3", "4"])]


def test_read_csv_refuses_a_cell_beyond_the_csv_limit(tmp_path):
    path = _file(tmp_path, "a,b\n1,2\n" + "x" * 200_000 + ",1\n", "t.csv")
    with pytest.raises(InputError, match=r"^" + str(path)) as exc:
        read_csv(path)
    assert "line 3: not a readable CSV file (a cell longer than 131,072" in str(exc.value)


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="reads /dev/zero")
def test_an_endless_input_is_refused_without_reading_it_all():
    """evaluate /dev/zero and calibrate /dev/zero read until memory ran out: an internal
    error (MemoryError), or the machine's memory exhausted."""
    with pytest.raises(InputError, match=r"^/dev/zero: larger than 64 MiB, not an input file$"):
        read_text("/dev/zero")
    with pytest.raises(InputError, match=r"^/dev/zero, line 1: longer than 1,048,576 char"):
        read_csv("/dev/zero")


def test_the_size_limits_themselves(tmp_path):
    document = _file(tmp_path, " " * (MAX_DOCUMENT_BYTES - 2) + "{}")
    assert read_json(document) == {}
    document.write_text(" " * (MAX_DOCUMENT_BYTES - 1) + "{}")
    with pytest.raises(InputError, match="larger than 64 MiB"):
        read_json(document)
    cells = ",".join(["1"] * (MAX_LINE_CHARS // 2))  # with its newline: the limit
    line = _file(tmp_path, "a\n" + cells + "\n", "t.csv")
    assert len(read_csv(line)[1][1]) == MAX_LINE_CHARS // 2
    line.write_text("a\n" + cells + "1\n")
    with pytest.raises(InputError, match="line 2: longer than 1,048,576 characters"):
        read_csv(line)


def test_write_json_refuses_non_finite_numbers_and_writes_nothing(tmp_path):
    path = tmp_path / "out.json"
    with pytest.raises(ValueError, match=r"predicted\.metrics\[1\] is nan") as exc:
        write_json(path, {"predicted": {"metrics": [1.0, math.nan]}})
    assert not isinstance(exc.value, InputError)  # our own NaN is an internal error
    assert list(tmp_path.iterdir()) == []


def test_an_output_that_is_a_folder_is_refused(tmp_path):
    folder = tmp_path / "out"
    folder.mkdir()
    with pytest.raises(InputError, match="is a folder; give the name of a file"):
        write_text(folder, "x")
    with pytest.raises(InputError, match="is a folder"):
        with atomic_path(folder):
            pass
    assert list(folder.iterdir()) == []


def test_read_config_builds_from_the_toml_and_names_the_file_in_a_refusal(tmp_path):
    path = tmp_path / "settings.toml"
    path.write_text("[run]\nsamples = 3\n")

    def parse(data):
        if data["run"]["samples"] < 4:
            raise InputError(f"run.samples: expected at least 4, got {data['run']['samples']}")
        return data["run"]["samples"]

    with pytest.raises(InputError) as refused:
        read_config(path, parse)
    assert str(refused.value) == f"{path}: run.samples: expected at least 4, got 3"
    path.write_text("[run]\nsamples = 8\n")
    assert read_config(path, parse) == 8
    path.write_text("[run\n")
    with pytest.raises(InputError, match="not valid TOML"):
        read_config(path, parse)
