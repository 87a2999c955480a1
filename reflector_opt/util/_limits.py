"""Limits on input: the physical range of the product and the size of the work of one run.

A value outside its physical range (a sensor 1e308 mm away, a pose of 120°) is a mistake,
however finite. A size parameter (a grid step, a number of samples, of sweep points, of
units) sets the memory and the time of a run; each is checked against the work it implies
*before* anything is allocated, so that a mistyped value (a step of 1e-7°, 10¹² samples) is
refused at once with a message naming it, instead of ending in a ``MemoryError`` or running
for hours. docs/conventions.md lists the limits.
"""

import math
import numbers

from reflector_opt.util._errors import InputError

#: Largest length or coordinate of a design, mm (a unit is tens of millimetres across).
MAX_LENGTH_MM = 1000.0
#: Pitch and roll lie strictly within ± this, degrees.
MAX_ANGLE_DEG = 90.0
#: Largest voltage of a read-out or a supply, V (a sensor works at a few volts).
MAX_VOLTS = 1000.0
#: Most units in one segment.
MAX_SEGMENT_UNITS = 1000
#: Most poses in one set: a pose grid or the random validation poses. The paper's ±15° at
#: 0.1° is 90,601; the metrics of a design take about 1.2 kB a pose, so a million (±15° at a
#: little over 0.03°) is about a gigabyte.
MAX_POSES = 1_000_000
#: Most simulated units of one tolerance study or sweep.
MAX_SIMULATED_UNITS = 100_000
#: Most model evaluations at a pose (units × poses each) of one study, sweep or search: at
#: about 1 µs each in one process (docs/performance-tolerance.md), from 20 minutes to an hour
#: on two cores.
MAX_POSE_EVALUATIONS = 2_000_000_000
#: Most points of one sweep grid.
MAX_SWEEP_POINTS = 10_000
#: Most segments of a circle in a printed part's mesh (a sphere has about this squared
#: triangles): a chord tolerance of about 0.00015 mm on an 11 mm sphere.
MAX_CIRCLE_SEGMENTS = 1024
#: Most worker processes.
MAX_WORKERS = 256
#: Most independent starts of one optimisation run.
MAX_STARTS = 256


def _shown(value):
    """``repr(value)``, or its order of magnitude for an integer of many digits."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 64:
        return f"about {'-' if value < 0 else ''}1e{int(value.bit_length() * math.log10(2))}"
    return repr(value)


def _amount(count):
    return f"{count:,.0f}" if count < 1e15 else f"{count:.3g}"


def check_finite(value, where):
    """A finite real number (not a bool) as a float.

    Parameters
    ----------
    value : object
    where : str
        What the value is, for the message (a field's path, ``"sensor 'X': current_gain"``).

    Returns
    -------
    float
        Raises :class:`~reflector_opt.util._errors.InputError` naming ``where`` for a value
        that is not a real number, an integer too large for a float, a NaN or an infinity.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InputError(f"{where}: expected a number, got {value!r}")
    try:
        value = float(value)
    except OverflowError:
        raise InputError(f"{where}: must be finite, got an integer too large for a float") from None
    if not math.isfinite(value):
        raise InputError(f"{where}: must be finite, got {value}")
    return value


def check_size(count, where, limit, what):
    """Refuse a size parameter whose work exceeds its limit, before anything is allocated.

    Parameters
    ----------
    count : int or float
        The size the parameter implies, e.g. the poses of a grid step (a float where the
        exact integer could be astronomically large).
    where : str
        The parameter as the user gives it, e.g. ``"workspace.step_deg"`` or ``"--samples"``.
    limit : int
        The largest size allowed (one of this module's ``MAX_`` constants).
    what : str
        What is counted, plural (``"poses"``).

    Returns
    -------
    int
        ``count``. Raises :class:`~reflector_opt.util._errors.InputError` naming ``where``,
        the size and the limit when ``count`` is larger than ``limit`` (or not a number).
    """
    if not count <= limit:
        raise InputError(
            f"{where}: asks for {_amount(count)} {what}, more than the limit of "
            f"{_amount(limit)} (docs/conventions.md, Limits)"
        )
    return int(count)


def check_count(value, where, low, high):
    """A whole number within ``[low, high]``, as an int.

    Parameters
    ----------
    value : object
        An int, or a float with a whole value (a JSON or TOML number); not a bool.
    where : str
        The parameter, for the message.
    low, high : int
        The range allowed.

    Returns
    -------
    int
        Raises :class:`~reflector_opt.util._errors.InputError` naming ``where`` and the range.
    """
    whole = isinstance(value, int) or (isinstance(value, float) and value.is_integer())
    if isinstance(value, bool) or not whole or not low <= value <= high:
        raise InputError(
            f"{where}: must be a whole number from {low:,} to {high:,}, got {_shown(value)}"
        )
    return int(value)


def check_within(value, where, bound, unit, *, strict=False, given=None):
    """A number within ±``bound`` (strictly with ``strict``), returned as it is.

    Parameters
    ----------
    value : float
    where : str
        The field, for the message (``"data.csv, line 4: column v1"``).
    bound : float
        The physical range of the field, in ``unit``.
    unit : str
        Written straight after the bound (``" V"``, ``"°"``).
    strict : bool
        The bound itself is outside the range (an angle of ±90°).
    given : str, optional
        The value as the user wrote it, for the message (default the value).

    Returns
    -------
    float
        Raises :class:`~reflector_opt.util._errors.InputError` naming ``where``, the range and
        the value (NaN is outside every range).
    """
    if not (abs(value) < bound if strict else abs(value) <= bound):
        within = f"> {-bound:g} and < {bound:g}" if strict else f"from {-bound:g} to {bound:g}"
        shown = value if given is None else given
        raise InputError(f"{where}: expected a number {within}{unit}, got {shown}")
    return value


def grid_poses(span_deg, step_deg):
    """Poses of a square-stepped grid over the given spans (both ends included).

    Parameters
    ----------
    span_deg : sequence of float
        Span of each angle, degrees.
    step_deg : float
        Grid step, degrees (positive).

    Returns
    -------
    float
        The number of poses, as a float (it may exceed any sensible integer).
    """
    counts = (span / step_deg for span in span_deg)
    return math.prod((round(n) if math.isfinite(n) else n) + 1.0 for n in counts)


#: What a search minimises (``--objective``). ``"in-use"`` (the default): the worst-case total
#: error in operating conditions, the default ones where none are given. ``"resolution"``: the
#: worst-case white-noise 1σ resolution, the conditions then only judging the result
#: (:func:`reflector_opt.optimiser._conditions.search_conditions`).
OBJECTIVES = ("in-use", "resolution")

#: Default chord tolerance between the printed parts' meshes and their true surfaces, mm.
DEFAULT_TOLERANCE_MM = 0.01
#: Coarsest chord tolerance the parts are built with, mm.
MAX_TOLERANCE_MM = 0.05
