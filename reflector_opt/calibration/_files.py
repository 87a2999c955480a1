"""CSV files of the lab: calibration samples, voltage logs and estimated angles.

Calibration CSV (one row per sample, several units per file, extra columns ignored)::

    unit,v1,v2,pitch_deg,roll_deg
    1,2.4790,2.4812,-15.0,-15.0

Voltage log (one row per unit and instant; ``sample`` or else ``time`` groups the rows of
one instant, without either the k-th row of every unit is instant k)::

    sample,unit,v1,v2
    0,1,2.4790,2.4812

Both may carry a ``temperature_c`` column, the unit's temperature at each row in °C (a
temperature-compensated calibration, :mod:`~reflector_opt.calibration._temperature`, needs it
in both); a value above 150 is refused as kelvin, one below −60 °C as implausible.

Errors name the file, the line (the header is line 1) and the column. Every row has at most
as many cells as the header (a stray comma, e.g. a decimal comma, would shift the cells
after it into the wrong columns); voltages lie within ±:data:`~reflector_opt.util._limits.MAX_VOLTS`
and angles strictly within ±:data:`~reflector_opt.util._limits.MAX_ANGLE_DEG`. A whole column
in another unit is refused before those, naming the likely unit
(:mod:`reflector_opt.util._units`): voltages beyond the sensors' supply (millivolts), pitch
and roll in radians; ``accept_units`` takes them as they are. All output is written
atomically (:mod:`reflector_opt.util._fileio`).
"""

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reflector_opt.calibration._temperature import DEFAULT_SUPPLY_V, check_temperature_c
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import read_csv, write_csv
from reflector_opt.util._limits import MAX_ANGLE_DEG, MAX_VOLTS, check_within
from reflector_opt.util._units import check_angles_deg, check_millivolts, check_supply_v

CALIBRATION_COLUMNS = ("unit", "v1", "v2", "pitch_deg", "roll_deg")
LOG_COLUMNS = ("unit", "v1", "v2")
LOG_KEYS = ("sample", "time")
_VOLTS = ("v1", "v2")
_ANGLE_COLUMNS = ("pitch_deg", "roll_deg")
#: The optional column of each row's temperature, °C.
TEMPERATURE = "temperature_c"

#: The columns of a calibration plan (``plan.csv``): the pose's number from 1, its angles.
PLAN_COLUMNS = ("pose", "pitch_deg", "roll_deg")
#: The optional column of a plan's temperature change from the calibration's T0, K.
TEMPERATURE_CHANGE = "temperature_change_k"
#: The largest temperature change a plan may hold, K.
_MAX_TEMPERATURE_CHANGE_K = 100.0

#: The range of each numeric column: (bound, the bound itself outside it, unit).
_RANGES = {
    "v1": (MAX_VOLTS, False, " V"),
    "v2": (MAX_VOLTS, False, " V"),
    "pitch_deg": (MAX_ANGLE_DEG, True, "°"),
    "roll_deg": (MAX_ANGLE_DEG, True, "°"),
    TEMPERATURE_CHANGE: (_MAX_TEMPERATURE_CHANGE_K, False, " K"),
}


def _read_table(path, required, numeric, optional=(), units=None):
    """Columns of a CSV file as lists (text) and float arrays, plus each row's line number.

    ``units``, a :class:`_Units`, checks the columns' units: first the whole columns (radians,
    millivolts), then each cell against its range in :data:`_RANGES`, then each voltage
    against the supply."""
    found = read_csv(path)  # before Path(), which would read '' as the current folder
    path = Path(path)
    if not found:
        raise InputError(f"{path}: empty file; expected a header with {', '.join(required)}")
    header_line, header = found[0][0], [cell.strip() for cell in found[0][1]]
    rows = [row for _, row in found[1:]]
    lines = [line for line, _ in found[1:]]
    duplicated = sorted({c for c in header if header.count(c) > 1 and c})
    if duplicated:
        raise InputError(f"{path}, line {header_line}: duplicate column(s) {', '.join(duplicated)}")
    missing = [c for c in required if c not in header]
    if missing:
        raise InputError(
            f"{path}, line {header_line}: missing column(s) {', '.join(missing)} "
            f"(expected {', '.join(required)})"
        )
    if not rows:
        raise InputError(f"{path}: no data rows after the header")
    wanted = [c for c in (*required, *optional) if c in header]
    index = {c: header.index(c) for c in wanted}
    columns = {c: [] for c in wanted}
    for row, line in zip(rows, lines, strict=True):
        if len(row) < len(header) or any(cell.strip() for cell in row[len(header) :]):
            raise InputError(
                f"{path}, line {line}: {len(row)} cells, the header has {len(header)} columns"
            )
        for c in wanted:
            columns[c].append(row[index[c]].strip())
    table = {}
    for c, cells in columns.items():
        if c in numeric:
            table[c] = _numbers(cells, c, lines, path)
        else:
            for cell, line in zip(cells, lines, strict=True):
                if not cell:
                    raise InputError(f"{path}, line {line}: column {c} is empty")
            table[c] = cells
    if units is not None:
        units.columns(table)
    for c in numeric:
        if c in table:
            _check_ranges(table[c], columns[c], c, lines, path)
    if units is not None:
        units.supply(table, lines)
    return table, np.array(lines)


def _numbers(cells, column, lines, path):
    """The cells of a numeric column as floats; an empty, text or non-finite cell refused."""
    values = np.empty(len(cells))
    for i, (cell, line) in enumerate(zip(cells, lines, strict=True)):
        if not cell:
            raise InputError(f"{path}, line {line}: column {column} is empty")
        try:
            value = float(cell)
        except ValueError:
            raise InputError(
                f"{path}, line {line}: column {column}: {cell!r} is not a number"
            ) from None
        if not math.isfinite(value):
            raise InputError(f"{path}, line {line}: column {column} is {cell} (not finite)")
        values[i] = value
    return values


def _check_ranges(values, cells, column, lines, path):
    """Each value of a numeric column within its physical range, naming its line."""
    for value, cell, line in zip(values, cells, lines, strict=True):
        where = f"{path}, line {line}: column {column}"
        if column in _RANGES:
            bound, strict, unit = _RANGES[column]
            check_within(value, where, bound, unit, strict=strict, given=cell)
        elif column == TEMPERATURE:
            check_temperature_c(value, where, given=cell)


@dataclass(frozen=True)
class _Units:
    """The unit checks of a table's columns (:mod:`reflector_opt.util._units`)."""

    path: object
    supply_v: float
    accept: bool
    angles: bool = False

    def _volts(self, table):
        return np.column_stack([table["v1"], table["v2"]])

    def columns(self, table):
        """Whole columns in another unit: millivolts, and pitch and roll in radians."""
        check_millivolts(self._volts(table), self.path, _VOLTS, self.supply_v, accept=self.accept)
        if self.angles:
            angles = np.column_stack([table[c] for c in _ANGLE_COLUMNS])
            check_angles_deg(angles, self.path, _ANGLE_COLUMNS, accept=self.accept)

    def supply(self, table, lines):
        """The first voltage beyond the supply, with its line."""
        rows = [f"line {line}" for line in lines]
        volts = self._volts(table)
        check_supply_v(volts, self.path, _VOLTS, self.supply_v, accept=self.accept, rows=rows)


@dataclass(frozen=True)
class UnitSamples:
    """Calibration samples of one unit.

    Attributes
    ----------
    volts : numpy.ndarray
        Shape (n, 2): v1, v2, V.
    angles_deg : numpy.ndarray
        Shape (n, 2): pitch, roll, degrees.
    lines : numpy.ndarray
        Shape (n,): line numbers in the file.
    temperature_c : numpy.ndarray or None
        Shape (n,): each sample's temperature, °C (None without the column).
    """

    volts: np.ndarray
    angles_deg: np.ndarray
    lines: np.ndarray
    temperature_c: np.ndarray | None = None


def read_calibration_csv(path, *, supply_v=DEFAULT_SUPPLY_V, accept_units=False):
    """Read a calibration CSV (columns unit, v1, v2, pitch_deg, roll_deg; optional temperature_c).

    Parameters
    ----------
    path : str or pathlib.Path
    supply_v : float, optional
        The sensors' supply, V: a voltage column beyond it is refused (millivolts, another
        circuit), as are pitch and roll in radians (:mod:`reflector_opt.util._units`).
    accept_units : bool, optional
        Take the columns as they are (``--accept-units``).

    Returns
    -------
    dict
        Unit label -> :class:`UnitSamples`, in order of first appearance.
    """
    numeric = (*CALIBRATION_COLUMNS[1:], TEMPERATURE)
    units = _Units(path, supply_v, accept_units, angles=True)
    table, lines = _read_table(
        path, CALIBRATION_COLUMNS, numeric, optional=(TEMPERATURE,), units=units
    )
    units = np.array(table["unit"])
    volts = np.column_stack([table["v1"], table["v2"]])
    angles = np.column_stack([table["pitch_deg"], table["roll_deg"]])
    temperature = table.get(TEMPERATURE)
    return {
        u: UnitSamples(
            volts[units == u],
            angles[units == u],
            lines[units == u],
            None if temperature is None else temperature[units == u],
        )
        for u in dict.fromkeys(table["unit"])  # in order of first appearance
    }


@dataclass(frozen=True)
class VoltageLog:
    """A voltage log arranged by instant and unit.

    Attributes
    ----------
    key : str
        Name of the column that identifies an instant (``"sample"``, ``"time"``, or
        ``"sample"`` numbered from 0 when the log has neither).
    instants : list of str
        The instants, in order of first appearance.
    units : list of str
        The units, in order of first appearance.
    volts : numpy.ndarray
        Shape (n_instants, n_units, 2), V.
    temperature_c : numpy.ndarray or None
        Shape (n_instants, n_units): each row's temperature, °C (None without the column).
    """

    key: str
    instants: list
    units: list
    volts: np.ndarray
    temperature_c: np.ndarray | None = None


def read_voltage_log(path, *, supply_v=DEFAULT_SUPPLY_V, accept_units=False):
    """Read a voltage log (columns unit, v1, v2; optional sample or time, and temperature_c).

    Every instant must have exactly one row per unit that appears in the log.

    Parameters
    ----------
    path : str or pathlib.Path
    supply_v : float, optional
        The sensors' supply, V: a voltage column beyond it is refused
        (:func:`~reflector_opt.util._units.check_supply_v`).
    accept_units : bool, optional
        Take the columns as they are (``--accept-units``).

    Returns
    -------
    VoltageLog
    """
    table, lines = _read_table(
        path,
        LOG_COLUMNS,
        ("v1", "v2", TEMPERATURE),
        optional=(*LOG_KEYS, TEMPERATURE),
        units=_Units(path, supply_v, accept_units),
    )
    units = list(dict.fromkeys(table["unit"]))  # in order of first appearance
    labels = np.array(table["unit"])
    # the temperature, if any, is arranged with the voltages as a third value of each row
    volts = np.column_stack([table[c] for c in ("v1", "v2", TEMPERATURE) if c in table])
    key = next((k for k in LOG_KEYS if k in table), None)
    if key is None:
        counts = {u: int(np.sum(labels == u)) for u in units}
        if len(set(counts.values())) > 1:
            listing = ", ".join(f"unit {u}: {n}" for u, n in counts.items())
            raise InputError(
                f"{path}: units have different numbers of rows ({listing}); add a sample "
                "column to say which rows belong together"
            )
        instants = [str(i) for i in range(counts[units[0]])]
        arranged = np.stack([volts[labels == u] for u in units], axis=1)
        return _log("sample", instants, units, arranged)
    instants = list(dict.fromkeys(table[key]))
    row_of = {k: i for i, k in enumerate(instants)}
    col_of = {u: j for j, u in enumerate(units)}
    arranged = np.full((len(instants), len(units), volts.shape[1]), np.nan)
    for k, u, v, line in zip(table[key], table["unit"], volts, lines, strict=True):
        cell = arranged[row_of[k], col_of[u]]
        if not np.isnan(cell[0]):
            raise InputError(f"{path}, line {line}: a second row for {key} {k}, unit {u}")
        arranged[row_of[k], col_of[u]] = v
    gaps = np.argwhere(np.isnan(arranged[..., 0]))
    if gaps.size:
        i, j = gaps[0]
        raise InputError(f"{path}: {key} {instants[i]} has no row for unit {units[j]}")
    return _log(key, instants, units, arranged)


def _log(key, instants, units, arranged):
    """A :class:`VoltageLog` of values arranged (instant, unit, v1 v2 [temperature])."""
    temperature = arranged[..., 2] if arranged.shape[-1] == 3 else None
    return VoltageLog(key, instants, units, arranged[..., :2], temperature)


def _with_temperature(header, rows, temperature_c):
    """Header and rows with a last ``temperature_c`` column, or unchanged without one."""
    if temperature_c is None:
        return header, rows
    cells = (repr(float(t)) for t in np.asarray(temperature_c, dtype=float))
    return (*header, TEMPERATURE), ((*row, t) for row, t in zip(rows, cells, strict=True))


def write_calibration_csv(path, unit, volts, angles_deg, temperature_c=None):
    """Write calibration samples in the format :func:`read_calibration_csv` reads.

    Parameters
    ----------
    path : str or pathlib.Path
    unit : array_like of str
        Shape (n,): unit labels.
    volts : array_like
        Shape (n, 2): v1, v2, V.
    angles_deg : array_like
        Shape (n, 2): pitch, roll, degrees.
    temperature_c : array_like, optional
        Shape (n,): each sample's temperature, °C (a ``temperature_c`` column).
    """
    volts = np.asarray(volts, dtype=float)
    angles = np.asarray(angles_deg, dtype=float)
    rows = (
        (u, repr(float(v[0])), repr(float(v[1])), repr(float(a[0])), repr(float(a[1])))
        for u, v, a in zip(unit, volts, angles, strict=True)
    )
    write_csv(path, *_with_temperature(CALIBRATION_COLUMNS, rows, temperature_c))


def write_voltage_log(path, sample, unit, volts, temperature_c=None):
    """Write a voltage log in the format :func:`read_voltage_log` reads.

    Parameters
    ----------
    path : str or pathlib.Path
    sample : array_like
        Shape (n,): instant of each row.
    unit : array_like of str
        Shape (n,): unit labels.
    volts : array_like
        Shape (n, 2): v1, v2, V.
    temperature_c : array_like, optional
        Shape (n,): each row's temperature, °C (a ``temperature_c`` column).
    """
    volts = np.asarray(volts, dtype=float)
    rows = (
        (s, u, repr(float(v[0])), repr(float(v[1])))
        for s, u, v in zip(sample, unit, volts, strict=True)
    )
    write_csv(path, *_with_temperature(("sample", *LOG_COLUMNS), rows, temperature_c))


def write_plan_csv(path, poses_deg, temperature_change_k=None):
    """Write a calibration plan (``plan.csv``, ``plan_temperature.csv``), atomically.

    Parameters
    ----------
    path : str or pathlib.Path
    poses_deg : array_like
        Shape (n, 2): pitch and roll of each pose in visiting order, degrees.
    temperature_change_k : array_like, optional
        Shape (n,): each pose's temperature change from the calibration's T0, K (the column
        ``temperature_change_k``).

    Notes
    -----
    Columns :data:`PLAN_COLUMNS` (the pose numbered from 1), then the temperature change;
    floats in Python's shortest round-trip representation, so :func:`read_plan_csv` gives
    back the same numbers.
    """
    poses = np.asarray(poses_deg, dtype=float).reshape(-1, 2)
    columns = [poses[:, 0], poses[:, 1]]
    header = PLAN_COLUMNS
    if temperature_change_k is not None:
        columns.append(np.asarray(temperature_change_k, dtype=float).reshape(len(poses)))
        header = (*header, TEMPERATURE_CHANGE)
    rows = (
        (i + 1, *(repr(float(v)) for v in values))
        for i, values in enumerate(zip(*columns, strict=True))
    )
    write_csv(path, header, rows)


def read_plan_csv(path):
    """Read a plan written by :func:`write_plan_csv`.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    poses_deg : numpy.ndarray
        Shape (n, 2): pitch and roll in the file's order, degrees.
    temperature_change_k : numpy.ndarray or None
        Shape (n,), K; None without the column.

    Raises
    ------
    InputError
        A missing column, an empty, text or non-finite cell, an angle not strictly within
        ±90° or a temperature change beyond ±100 K, naming the file, line and column; angle
        columns that look like radians.
    """
    angles = ("pitch_deg", "roll_deg")
    table, _ = _read_table(path, angles, (*angles, TEMPERATURE_CHANGE), (TEMPERATURE_CHANGE,))
    poses = np.column_stack([table[c] for c in angles])
    check_angles_deg(poses, Path(path), angles)
    return poses, table.get(TEMPERATURE_CHANGE)
