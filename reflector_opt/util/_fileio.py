"""File input and output with errors a user can act on.

Output is atomic: written to a temporary file beside the target, then renamed, so a failure
part-way (a full disk, an exception while serialising) leaves the target as it was and no
truncated file behind; a target that is a folder is refused. Input of text, JSON, TOML and
CSV turns every failure into one :class:`~reflector_opt.util._errors.InputError` naming the
file: unreadable or non-UTF-8 files, syntax errors, JSON objects with a repeated key, nesting
deeper than :data:`MAX_DEPTH`, numbers that are not finite or too large for a float, CSV cells
longer than the csv module's limit. What a reader returns holds only finite numbers.
"""

import csv
import dataclasses
import json
import math
import os
import sys
import tempfile
import tomllib
import typing
from contextlib import contextmanager
from pathlib import Path

import msgspec

from reflector_opt.util._atomic import (
    cannot_write,
    new_mode,
    new_parents,
    remove_leftovers,
    temporary_prefix,
)
from reflector_opt.util._errors import InputError

#: Deepest nesting of objects and arrays in a JSON or TOML input.
MAX_DEPTH = 64
#: Largest JSON or TOML input, bytes (a design or a coefficient file is a few kilobytes).
MAX_DOCUMENT_BYTES = 64 << 20
#: Longest line of a CSV input, characters (a row of a lab file is under a hundred).
MAX_LINE_CHARS = 1 << 20


def json_number(value):
    """``value`` as a float for a JSON document, or None where it is not finite.

    JSON has no NaN or infinity; a figure that is not finite (a resolution where the
    Jacobian is singular, a ratio of an empty mean) is written as ``null``.

    Parameters
    ----------
    value : float or numpy scalar

    Returns
    -------
    float or None
    """
    value = float(value)
    return value if math.isfinite(value) else None


def json_record(record):
    """A dataclass's fields as a JSON-ready dict, in their order: lists and tuples as new lists,
    floats that are not finite as None.

    Parameters
    ----------
    record : dataclass instance

    Returns
    -------
    dict
    """
    return {
        f.name: list(v)
        if isinstance(v, tuple | list)
        else json_number(v)
        if isinstance(v, float)
        else v
        for f in dataclasses.fields(record)
        for v in (getattr(record, f.name),)
    }


class Record(msgspec.Struct, frozen=True, kw_only=True):
    """A typed, frozen result block: its fields are read by attribute (units in their names),
    :meth:`to_dict` gives its JSON in the fields' order, a field left ``msgspec.UNSET`` out of
    it, and :meth:`from_dict` reads that JSON back."""

    def to_dict(self):
        """JSON-ready: nested records (each by its own ``to_dict``) and lists as dicts and
        lists, numpy numbers as Python's."""
        out = {}
        for name in self.__struct_fields__:
            value = getattr(self, name)
            if value is not msgspec.UNSET:
                out[name] = (
                    value.to_dict()
                    if isinstance(value, Record)
                    else msgspec.to_builtins(value, enc_hook=lambda number: number.item())
                )
        return out

    @classmethod
    def from_dict(cls, data):
        """The record of a JSON-ready dict (:class:`msgspec.ValidationError` where it is not)."""
        return msgspec.convert(data, cls, strict=False)


class Kept(Record, kw_only=True):
    """A record read from a file that keeps what this release does not write.

    A key no field names is kept as read, in ``others``, and written back after the fields,
    so a file of any earlier release loads and is saved again with the same content; a field
    that is itself a :class:`Kept` record keeps its own.
    """

    others: dict = msgspec.field(default_factory=dict)

    def to_dict(self):
        """The block as the file holds it: the fields set, then the keys kept."""
        return {k: v for k, v in super().to_dict().items() if k != "others"} | self.others

    @classmethod
    def from_dict(cls, data, where=""):
        """The record of a block read from a file; InputError naming the key that does not
        fit (``where`` the block's own path)."""
        from reflector_opt.util._schema import convert

        fields = {f.name: f.type for f in msgspec.structs.fields(cls) if f.name != "others"}
        read = {}
        for name, kind in fields.items():
            if name in data:
                nested = [t for t in typing.get_args(kind) if isinstance(t, type)]
                nested = next((t for t in nested if issubclass(t, Kept)), None)
                value = data[name]
                read[name] = (
                    nested.from_dict(value, f"{where}.{name}")
                    if nested and isinstance(value, dict)
                    else value
                )
        others = {k: v for k, v in data.items() if k not in fields}
        return convert({**read, "others": others}, cls, where=where, strict=False)


@contextmanager
def atomic_path(path, suffix=""):
    """Yield a temporary path in the target's folder; rename it onto ``path`` on success.

    Parameters
    ----------
    path : str or pathlib.Path
        Final file path. Its folder is created if missing, and removed again (with the
        parents created for it) if the write fails: a refused write leaves no folder.
    suffix : str, optional
        Suffix for the temporary file (some writers infer the format from it).

    Yields
    ------
    pathlib.Path
        Where the caller writes; removed if the body raises.
    """
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{path}: is a folder; give the name of a file to write")
    with new_parents(path):
        remove_leftovers(path)
        try:
            fd, tmp = tempfile.mkstemp(
                prefix=temporary_prefix(path), suffix=suffix, dir=path.parent
            )
        except OSError as exc:
            raise InputError(f"cannot write {path}: {exc.strerror or exc}") from None
        os.close(fd)
        tmp = Path(tmp)
        try:
            yield tmp
            os.chmod(tmp, new_mode(0o666))
            os.replace(tmp, path)
        except OSError as exc:
            raise cannot_write(path, exc) or exc from None
        finally:
            tmp.unlink(missing_ok=True)


def write_file(path, write, suffix=""):
    """Write ``path`` atomically by ``write(tmp)`` (:func:`atomic_path`); any ``OSError`` of
    the write is an :class:`~reflector_opt.util._errors.InputError` naming ``path``."""
    try:
        with atomic_path(path, suffix=suffix) as tmp:
            write(tmp)
    except OSError as exc:
        raise InputError(f"cannot write {path}: {exc.strerror or exc}") from None


def write_text(path, text):
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def write_json(path, data):
    """Write ``data`` as indented JSON to ``path`` atomically.

    A NaN or infinite number is refused (JSON has neither): ``ValueError`` naming its key,
    and nothing is written.
    """
    try:
        text = json.dumps(data, indent=2, allow_nan=False)
    except ValueError:
        found = _first_non_finite(data)
        if found is None:
            raise
        where, value = found
        raise ValueError(
            f"cannot write {path}: {where or 'the document'} is {value}, and JSON holds only "
            "finite numbers"
        ) from None
    write_text(path, text + "\n")


def _first_non_finite(data):
    """Key path and value of the first non-finite float in a JSON-like tree, or None."""
    for where, value, _ in _walk(data):
        if isinstance(value, float) and not math.isfinite(value):
            return where, value
    return None


def _walk(data):
    """Every node of a JSON-like tree as (key path, value, depth), depth first, iteratively."""
    stack = [("", data, 0)]
    while stack:
        where, value, depth = stack.pop()
        yield where, value, depth
        if isinstance(value, dict):
            children = [(f"{where}.{k}" if where else str(k), v) for k, v in value.items()]
        elif isinstance(value, list | tuple):
            children = [(f"{where}[{i}]", v) for i, v in enumerate(value)]
        else:
            continue
        stack.extend((w, v, depth + 1) for w, v in reversed(children))


def _input_path(path):
    """``path`` as a Path; an empty name (which Path reads as the current folder) is refused."""
    if isinstance(path, str) and not path.strip():
        raise InputError(f"cannot read {path!r}: an empty file name")
    return Path(path)


def read_text(path):
    """Read a UTF-8 text file of at most :data:`MAX_DOCUMENT_BYTES`; an unreadable, non-text
    or larger file (``/dev/zero`` included) is an InputError."""
    path = _input_path(path)
    try:
        with path.open("rb") as handle:
            data = handle.read(MAX_DOCUMENT_BYTES + 1)
    except OSError as exc:
        raise InputError(f"cannot read {path}: {exc.strerror or exc}") from None
    if len(data) > MAX_DOCUMENT_BYTES:
        raise InputError(f"{path}: larger than {MAX_DOCUMENT_BYTES >> 20} MiB, not an input file")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a UTF-8 text file") from None


class LineTooLong(csv.Error):
    """A line of a CSV input longer than :data:`MAX_LINE_CHARS`."""


def bounded_lines(handle):
    """The lines of a text file, for :func:`csv.reader`, each read with at most
    :data:`MAX_LINE_CHARS` characters: iterating the file would read a line without end
    (``/dev/zero``) until memory runs out. A longer line raises :class:`LineTooLong`."""
    while line := handle.readline(MAX_LINE_CHARS + 1):
        if len(line) > MAX_LINE_CHARS:
            raise LineTooLong
        yield line


class _Refused(Exception):
    """A value a JSON hook refuses; read_json names the file."""


def _unique_keys(pairs):
    data = {}
    for key, value in pairs:
        if key in data:
            raise _Refused(f"the key {key!r} appears twice in one object")
        data[key] = value
    return data


def _json_int(text):
    """An integer; one of more than 400 digits (beyond any float) stands as 10**400, which
    :func:`_check_tree` refuses by its key."""
    return int(text) if len(text.lstrip("-")) <= 400 else 10**400


_FINITE = f"numbers must be finite and within ±{sys.float_info.max:.4g}"


def _check_tree(data, path):
    """Refuse non-finite numbers, numbers too large for a float and too deep nesting."""
    for where, value, depth in _walk(data):
        if depth > MAX_DEPTH:
            raise InputError(f"{path}: nested more than {MAX_DEPTH} levels deep at {where}")
        if isinstance(value, bool):
            continue
        if isinstance(value, int) and abs(value) > sys.float_info.max:
            raise InputError(f"{path}: {where}: the number is too large: {_FINITE}")
        if isinstance(value, float) and not math.isfinite(value):
            raise InputError(f"{path}: {where}: got {value}; {_FINITE}")
    return data


def read_json(path):
    """Parse a JSON file into plain Python values, or raise an InputError naming the problem.

    Refused: invalid JSON (with its line), a key repeated within one object, nesting deeper
    than :data:`MAX_DEPTH`, ``NaN``, ``Infinity`` and numbers beyond the float range.
    """
    text = read_text(path)
    try:
        data = json.loads(text, object_pairs_hook=_unique_keys, parse_int=_json_int)
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: not valid JSON ({exc.msg} at line {exc.lineno})") from None
    except _Refused as exc:
        raise InputError(f"{path}: {exc}") from None
    except RecursionError:
        raise InputError(f"{path}: nested more than {MAX_DEPTH} levels deep") from None
    return _check_tree(data, path)


def read_toml(path):
    """Parse a TOML file (:mod:`tomllib`), or raise an InputError naming the problem.

    Refused: invalid TOML (repeated keys included), nesting deeper than :data:`MAX_DEPTH`,
    ``nan``, ``inf`` and integers beyond the float range.
    """
    text = read_text(path)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: not valid TOML ({exc})") from None
    except ValueError:  # an integer of more digits than int() reads
        raise InputError(f"{path}: a number is too large: {_FINITE}") from None
    except RecursionError:
        raise InputError(f"{path}: nested more than {MAX_DEPTH} levels deep") from None
    return _check_tree(data, path)


def read_config(path, parse):
    """A config file read as TOML (:func:`read_toml`) and built by ``parse``.

    Parameters
    ----------
    path : str or pathlib.Path
        A TOML file.
    parse : callable
        ``parse(data)`` builds the config from the parsed document, raising an InputError
        that names the section and key at fault.

    Returns
    -------
    object
        What ``parse`` returns; its InputError is raised again, of the same class, with the
        file's path first.
    """
    data = read_toml(path)
    try:
        return parse(data)
    except InputError as exc:
        raise type(exc)(f"{path}: {exc}") from None


def write_csv(path, header, rows):
    """Write rows under a header as CSV, atomically (temporary file, then rename).

    Parameters
    ----------
    path : str or pathlib.Path
    header : sequence of str
    rows : iterable of sequences
        The cells of each row, written as :mod:`csv` writes them (give floats as
        ``repr(x)`` for Python's shortest round-trip form).
    """
    with atomic_path(path, suffix=".csv") as tmp:
        with tmp.open("w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle)
            writer.writerow(header)
            writer.writerows(rows)


def read_csv(path):
    """The non-blank rows of a UTF-8 CSV file (a byte-order mark is allowed), with line numbers.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    list of (int, list of str)
        Each non-blank row's line number in the file and its cells, the header first.
        Raises :class:`~reflector_opt.util._errors.InputError` naming the file (and the line)
        if it cannot be read, is not UTF-8 text or is not CSV (e.g. a cell longer than
        :func:`csv.field_size_limit` characters, a line longer than :data:`MAX_LINE_CHARS`).
    """
    path = _input_path(path)
    rows, line = [], 0
    try:
        with path.open(newline="", encoding="utf-8-sig") as handle:
            reader = csv.reader(bounded_lines(handle))
            for row in reader:
                line = reader.line_num
                if any(cell.strip() for cell in row):
                    rows.append((line, row))
    except LineTooLong:
        raise InputError(
            f"{path}, line {line + 1}: longer than {MAX_LINE_CHARS:,} characters, not a CSV line"
        ) from None
    except OSError as exc:
        raise InputError(f"cannot read {path}: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a UTF-8 text file") from None
    except csv.Error as exc:
        reason = str(exc)
        if "field larger than field limit" in reason:
            reason = f"a cell longer than {csv.field_size_limit():,} characters"
        raise InputError(f"{path}, line {line + 1}: not a readable CSV file ({reason})") from None
    return rows
