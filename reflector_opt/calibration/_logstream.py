"""Voltage logs read, and angle tables written, block by block in bounded memory.

A log whose rows of one instant are together — consecutive rows with the same ``sample``
(or ``time``), or without either column one row of every unit in turn — is read in blocks
of about :data:`BLOCK_BYTES` with pyarrow's streaming CSV reader (:func:`log_blocks`), so
the memory an estimate needs does not grow with the log; a ``temperature_c`` column is read
with the voltages. Anything else — rows of an instant apart, a unit missing or repeated, a
cell that is not a finite number, a voltage or a temperature out of range, a malformed line —
raises :class:`Unordered`; the caller then reads the log whole
(:func:`~reflector_opt.calibration._files.read_voltage_log`), which accepts any order and
names the line and column of an error. :func:`write_angles` appends rows of an angle table
with pyarrow's CSV writer.
"""

import csv

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pcsv

from reflector_opt.calibration._files import LOG_COLUMNS, LOG_KEYS, TEMPERATURE, VoltageLog
from reflector_opt.calibration._temperature import KELVIN_LIKE_C, MIN_TEMPERATURE_C
from reflector_opt.util._fileio import bounded_lines
from reflector_opt.util._limits import MAX_VOLTS

#: Bytes of the log parsed at a time.
BLOCK_BYTES = 1 << 18

_SPECIAL = '[,"\r\n]'  # an instant with one of these is quoted


class Unordered(Exception):
    """The log cannot be streamed; read it whole for the result or the precise error."""


def _header(path):
    """The header's cells and its line number (blank lines before it skipped)."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as handle:
            reader = csv.reader(bounded_lines(handle))  # a LineTooLong is a csv.Error
            for row in reader:
                if any(cell.strip() for cell in row):
                    return [cell.strip() for cell in row], reader.line_num
    except (OSError, UnicodeDecodeError, csv.Error):
        pass
    raise Unordered


def _batches(path, header, header_line, wanted, block_bytes):
    read = pcsv.ReadOptions(
        column_names=[f"c{i}" for i in range(len(header))],
        skip_rows=header_line,
        block_size=block_bytes,
        use_threads=False,
    )
    names = {c: f"c{header.index(c)}" for c in wanted}
    convert = pcsv.ConvertOptions(
        column_types={name: pa.string() for name in names.values()},
        include_columns=list(names.values()),
        strings_can_be_null=False,
        quoted_strings_can_be_null=False,
    )
    try:
        reader = pcsv.open_csv(path, read_options=read, convert_options=convert)
        for batch in reader:
            yield {c: batch.column(name) for c, name in names.items()}
    except (pa.ArrowInvalid, OSError) as exc:
        raise Unordered from exc


def _text(column):
    column = pc.utf8_trim_whitespace(column)
    if len(column) and pc.min(pc.utf8_length(column)).as_py() == 0:
        raise Unordered  # an empty cell
    return column


def _values(columns):
    """Each row's v1, v2 and, in a log with the column, temperature, shape (n_rows, 2 or 3).

    Raises :class:`Unordered` for a value out of its range (NaN and infinities too)."""
    names = [c for c in ("v1", "v2", TEMPERATURE) if c in columns]
    try:
        values = np.column_stack(
            [_numpy(pc.cast(columns[c], pa.float64()), np.float64) for c in names]
        )
    except (pa.ArrowInvalid, pa.ArrowNotImplementedError) as exc:
        raise Unordered from exc
    volts_within = (np.abs(values[:, :2]) <= MAX_VOLTS).all()  # not NaN, infinite or beyond
    t = values[:, 2:]  # the temperature, in a log with the column
    if not (volts_within and ((t >= MIN_TEMPERATURE_C) & (t <= KELVIN_LIKE_C)).all()):
        raise Unordered
    return values


def _numpy(array, dtype):
    """The values of a pyarrow array of fixed-width numbers without nulls, as numpy's.

    Read from the data buffer directly: pyarrow's own conversion imports pandas.
    """
    data = np.frombuffer(array.buffers()[1], dtype=dtype)
    return data[array.offset : array.offset + len(array)]


def _true_at(mask):
    """Indices where a pyarrow boolean array is true, as a numpy array."""
    return _numpy(pc.indices_nonzero(mask), np.uint64).astype(np.int64)


def _concat(carry, columns):
    if carry is None:
        return columns
    return {c: pa.concat_arrays([carry[c], columns[c]]) for c in columns}


def _slice(columns, start, stop=None):
    return {c: v.slice(start, None if stop is None else stop - start) for c, v in columns.items()}


def _first_instant(units, key_values):
    """Labels of the first instant: the units up to the first repeat (or change of key)."""
    if key_values is not None:
        n = len(key_values)
        same = _true_at(pc.not_equal(key_values, key_values[0]))
        end = int(same[0]) if same.size else n
        labels = units.slice(0, end).to_pylist()
        return labels if len(set(labels)) == len(labels) and end < n else None
    seen = []
    for label in units.to_pylist():
        if label in seen:
            return seen
        seen.append(label)
    return None


def log_blocks(path, block_bytes=BLOCK_BYTES):
    """The instants of a voltage log in blocks, read in bounded memory.

    Parameters
    ----------
    path : str or pathlib.Path
        Voltage log (the format of
        :func:`~reflector_opt.calibration._files.read_voltage_log`).
    block_bytes : int
        Bytes parsed at a time.

    Yields
    ------
    VoltageLog
        Consecutive complete instants (their ``volts`` of shape (n, n_units, 2), V); the
        units in order of first appearance, the same in every block.

    Raises
    ------
    Unordered
        The log is not one that can be streamed (see the module's description), possibly
        after some blocks were yielded.
    """
    header, header_line = _header(path)
    if len(set(header)) != len(header) or any(c not in header for c in LOG_COLUMNS):
        raise Unordered
    key = next((k for k in LOG_KEYS if k in header), None)
    optional = (TEMPERATURE,) if TEMPERATURE in header else ()
    wanted = [c for c in (key, *LOG_COLUMNS, *optional) if c is not None]
    units, position, carry, counter = None, None, None, 0
    batches = _batches(path, header, header_line, wanted, block_bytes)
    for last, columns in _lookahead(batches):
        columns = _concat(carry, {c: _text(v) for c, v in columns.items()})
        n_rows = len(columns["unit"])
        if units is None:
            units = _first_instant(columns["unit"], columns.get(key))
            if units is None:
                if last:
                    raise Unordered  # a log of one instant: read it whole
                carry = columns
                continue
            position = {u: i for i, u in enumerate(units)}
        starts = _instant_starts(columns.get(key), n_rows, len(units), last)
        complete = int(starts[-1])
        carry = _slice(columns, complete) if complete < n_rows else None
        if complete == 0:
            continue
        block = _slice(columns, 0, complete)
        yield _block_log(block, key, starts, units, position, counter)
        counter += len(starts) - 1
    if units is None:
        raise Unordered


def _instant_starts(key_values, n_rows, n_units, last):
    """Row where each complete instant of a block starts, and the end of the last one.

    Without a key every ``n_units`` rows are an instant; with one, an instant ends where the
    key changes, and the block's last instant may go on in the next block unless ``last``.
    Raises :class:`Unordered` unless every instant has ``n_units`` rows.
    """
    if key_values is None:
        complete = n_rows if last else n_rows - n_rows % n_units
        if complete % n_units:
            raise Unordered
        return np.arange(0, complete + 1, n_units)
    change = pc.not_equal(key_values.slice(1), key_values.slice(0, n_rows - 1))
    starts = np.concatenate([[0], _true_at(change) + 1, [n_rows]])
    if not last:
        starts = starts[:-1]  # the last instant may go on in the next block
    if np.any(np.diff(starts) != n_units):
        raise Unordered
    return starts


def _block_log(block, key, starts, units, position, counter):
    """The :class:`VoltageLog` of a block of complete instants, the units in ``units`` order.

    ``counter`` numbers the first instant of a log without a key. Raises :class:`Unordered`
    unless every instant holds each unit once.
    """
    n = len(units)
    encoded = pc.dictionary_encode(block["unit"])
    lookup = np.array([position.get(u, -1) for u in encoded.dictionary.to_pylist()])
    order = lookup[_numpy(encoded.indices, np.int32)].reshape(-1, n)
    if (np.sort(order, axis=1) != np.arange(n)).any():
        raise Unordered
    values = _values(block)
    arranged = np.empty((len(order), n, values.shape[1]))
    arranged[np.arange(len(order))[:, None], order] = values.reshape(-1, n, values.shape[1])
    if key is None:
        instants = pa.array(np.arange(counter, counter + len(order)).astype(str))
    else:
        instants = block[key].take(pa.array(starts[:-1]))
    temperature = arranged[..., 2] if values.shape[1] == 3 else None
    return VoltageLog(key or "sample", instants, units, arranged[..., :2], temperature)


def _lookahead(iterable):
    """Pairs (is_last, item)."""
    iterator = iter(iterable)
    try:
        item = next(iterator)
    except StopIteration:
        return
    for following in iterator:
        yield False, item
        item = following
    yield True, item


def write_angles(handle, instants, table):
    """Append rows of an angle table to an open binary file.

    Parameters
    ----------
    handle : file
        Open for binary writing.
    instants : pyarrow.Array or sequence of str
        The instant of each row (first column).
    table : numpy.ndarray
        Shape (n_rows, n_columns): the numbers of each row, written in their shortest
        round-trip form.
    """
    instants = pa.array(instants, type=pa.string())
    columns = {"instant": instants} | {f"c{j}": table[:, j] for j in range(table.shape[1])}
    special = len(instants) > 0 and pc.any(pc.match_substring_regex(instants, _SPECIAL)).as_py()
    options = pcsv.WriteOptions(include_header=False, quoting_style="needed" if special else "none")
    pcsv.write_csv(pa.table(columns), handle, options)
