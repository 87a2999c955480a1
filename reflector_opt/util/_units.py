"""Units of the columns of input files: values that read as another unit are refused.

A column's name states its unit (``distance_mm``, ``v1`` in volts, ``pitch_deg``), but a file
written in metres, millivolts or radians has values of the right kind in the wrong unit, and
every cell of it is a plausible number: only the whole column shows the mistake. Each check
here looks at a whole column and refuses, in one line naming the file, the column and the
unit the values most likely are in, a column that cannot be in its own unit:

* **distances, mm** (flat-target curves): the sensors read 0.5–3 mm; a curve whose largest
  distance is below :data:`METRES_LIKE_MM` is in metres, one whose smallest is above
  :data:`MICROMETRES_LIKE_MM` in micrometres;
* **voltages, V** (calibration data, voltage logs, curves): a read-out lies between 0 and its
  supply (the output is clamped to [V_CE(sat), Vcc], docs/model.md); a column beyond the
  supply by more than :data:`SUPPLY_MARGIN` of it is refused, as millivolts where the values
  fit the supply in mV;
* **angles, degrees** (calibration data): pitch and roll all within ±:data:`RADIANS_LIKE_DEG`
  are radians (a ±15° workspace is ±0.26 rad, and no calibration spans less than a degree).

A user whose file is right (a bench with another supply, say) passes ``--accept-units``
(:data:`ACCEPT_OPTION`), the one name of the option in every command that reads such a file;
each check then returns without a word.
"""

from reflector_opt.util._errors import InputError

#: The option that takes a column's values as they are, in every command.
ACCEPT_OPTION = "--accept-units"
#: A curve whose every distance is below this, mm, is in metres (3 mm is 0.003 m).
METRES_LIKE_MM = 0.05
#: A curve whose every distance is above this, mm, is in micrometres (0.5 mm is 500 µm).
MICROMETRES_LIKE_MM = 50.0
#: Pitch and roll all within ± this, degrees, are radians.
RADIANS_LIKE_DEG = 0.6
#: Share of the supply a reading may lie beyond 0 or the supply (noise, an output offset).
SUPPLY_MARGIN = 0.05


class UnitsError(InputError):
    """A column whose values are in another unit than the one its name states."""


def _refuse(where, what, likely, accept):
    if not accept:
        raise UnitsError(f"{where}: {what}: {likely}, or pass {ACCEPT_OPTION} if they are right")


def _span(values):
    import numpy as np  # here: the command line's parsers read ACCEPT_OPTION without numpy

    values = np.asarray(values, dtype=float)
    return float(values.min()), float(values.max())


def _by_column(values, columns):
    """The values as a float array of one column per name: shape (rows, len(columns))."""
    import numpy as np

    return np.asarray(values, dtype=float).reshape(-1, len(columns))


def check_distances_mm(distance_mm, where, column="distance_mm", *, accept=False):
    """Refuse a column of distances that reads as metres or micrometres, not millimetres.

    Parameters
    ----------
    distance_mm : array_like
        The column's values, as given (meant in mm).
    where : str
        The file, for the message.
    column : str
        The column's name.
    accept : bool
        Take the values as they are (``--accept-units``).

    Raises
    ------
    UnitsError
        Every distance below :data:`METRES_LIKE_MM` (metres) or above
        :data:`MICROMETRES_LIKE_MM` (micrometres).
    """
    low, high = _span(distance_mm)
    what = f"column {column} spans {low:g}–{high:g}"
    if high < METRES_LIKE_MM:
        _refuse(where, what, "that looks like metres; give millimetres (×1000)", accept)
    elif low > MICROMETRES_LIKE_MM:
        _refuse(where, what, "that looks like micrometres; give millimetres (÷1000)", accept)


def check_millivolts(volts, where, columns, supply_v, *, accept=False):
    """Refuse voltage columns that read as millivolts of the supply, not volts.

    Parameters
    ----------
    volts : array_like
        Shape (..., len(columns)): the columns' values, as given (meant in V).
    where : str
        The file, for the message.
    columns : sequence of str
        The columns' names, along the last axis of ``volts``.
    supply_v : float
        The sensors' supply, V.
    accept : bool
        Take the values as they are (``--accept-units``).

    Raises
    ------
    UnitsError
        A column whose values all lie within the supply in mV (give or take
        :data:`SUPPLY_MARGIN`) and reach beyond ten times the supply in V.
    """
    margin = SUPPLY_MARGIN * supply_v
    for column, values in zip(columns, _by_column(volts, columns).T, strict=True):
        low, high = _span(values)
        if low >= -1e3 * margin and 10 * supply_v < high <= 1e3 * (supply_v + margin):
            what = f"column {column} spans {low:g}–{high:g}, beyond the {supply_v:g} V supply"
            _refuse(where, what, "that looks like millivolts; give volts (÷1000)", accept)


def check_supply_v(volts, where, columns, supply_v, *, accept=False, rows=None):
    """Refuse a voltage beyond the supply: millivolts, or another circuit's reading.

    Parameters
    ----------
    volts : array_like
        Shape (..., len(columns)): the columns' values, as given (meant in V).
    where : str
        The file, for the message.
    columns : sequence of str
        The columns' names, along the last axis of ``volts``.
    supply_v : float
        The sensors' supply, V; a reading lies within [0, supply_v] (the output is clamped to
        [V_CE(sat), Vcc]), give or take :data:`SUPPLY_MARGIN` of it.
    accept : bool
        Take the values as they are (``--accept-units``).
    rows : sequence of str, optional
        How to name each row of ``volts`` in the message (``"line 7"``); without them the
        message gives the column's span.

    Raises
    ------
    UnitsError
        A column in millivolts (:func:`check_millivolts`), else the first value beyond the
        margin, naming its column (and row).
    """
    import numpy as np

    check_millivolts(volts, where, columns, supply_v, accept=accept)
    volts = _by_column(volts, columns)
    margin = SUPPLY_MARGIN * supply_v
    outside = (volts < -margin) | (volts > supply_v + margin)
    if accept or not outside.any():
        return
    i, j = np.argwhere(outside)[0]
    if rows is None:
        low, high = _span(volts[:, j])
        what = f"column {columns[j]} spans {low:g}–{high:g}"
    else:
        what = f"{rows[i]}: column {columns[j]} is {volts[i, j]:g}"
    what += f", beyond the {supply_v:g} V supply (0 to {supply_v:g} V ± {margin:.2g} V)"
    _refuse(where, what, "not a reading of this circuit; give its output in volts", accept)


def check_angles_deg(angles_deg, where, columns, *, accept=False):
    """Refuse angle columns that all lie within ±0.6: radians, not degrees.

    Parameters
    ----------
    angles_deg : array_like
        Shape (..., len(columns)): the columns' values, as given (meant in degrees).
    where : str
        The file, for the message.
    columns : sequence of str
        The columns' names, along the last axis.
    accept : bool
        Take the values as they are (``--accept-units``).

    Raises
    ------
    UnitsError
        Every value of every column within ±:data:`RADIANS_LIKE_DEG`, and one not zero.
    """
    import numpy as np

    angles = np.abs(_by_column(angles_deg, columns))
    span = angles.max(axis=0)
    if np.all(span <= RADIANS_LIKE_DEG) and np.any(span > 0.0):
        what = (
            f"columns {' and '.join(columns)} are all within ±{RADIANS_LIKE_DEG:g} "
            f"(largest {span.max():.3g})"
        )
        _refuse(where, what, "they look like radians; give degrees", accept)
