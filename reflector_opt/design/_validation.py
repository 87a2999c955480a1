"""Value checks shared by the parts of a design, with messages that name the field.

Each check takes the value and ``where``, the field's path in ``design.json`` (e.g.
``"reflector.centre_mm"``), and raises :class:`~reflector_opt.util._errors.InputError`
naming that path when the value is wrong.
"""

import math
import re

from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import MAX_LENGTH_MM, check_finite

#: Largest component of a direction vector (only its direction counts; this keeps its norm
#: finite).
DIRECTION_BOUND = 1e6


def check_number(value, where, *, positive=False, nonnegative=False, bound=None, unit=""):
    """A finite number (not a bool) as a float, optionally positive, non-negative, bounded.

    Parameters
    ----------
    value : object
    where : str
        The field's path, for the message.
    positive, nonnegative : bool
        Require ``value > 0`` or ``value >= 0``.
    bound : float, optional
        Require ``|value| <= bound``: the physical range of the field.
    unit : str
        Unit of ``bound`` in the message (``"mm"``).

    Returns
    -------
    float
        Raises :class:`~reflector_opt.util._errors.InputError` naming ``where``.
    """
    value = check_finite(value, where)
    if positive and value <= 0:
        raise InputError(f"{where}: must be positive, got {value}")
    if nonnegative and value < 0:
        raise InputError(f"{where}: must not be negative, got {value}")
    if bound is not None and abs(value) > bound:
        shown = f"within ±{bound:g}" if not (positive or nonnegative) else f"at most {bound:g}"
        raise InputError(f"{where}: must be {shown}{' ' + unit if unit else ''}, got {value:g}")
    return value


def check_centre_inside(radius_mm, centre_mm):
    """The rotation centre O strictly inside the reflector sphere.

    The reflector turns about O on the bearing, which its shell encloses: a sphere of
    radius ``radius_mm`` (mm) centred at ``centre_mm`` (mm, from O) that does not enclose O
    cannot be built, and its sections through O are undefined.
    """
    offset = math.hypot(*centre_mm)
    if not offset < radius_mm:
        raise InputError(
            f"reflector.centre_mm: the rotation centre must lie inside the sphere: the centre "
            f"is {offset:.4g} mm from it, reflector.radius_mm is {radius_mm:g} mm"
        )


def check_length(value, where, *, positive=False, nonnegative=False):
    """A length or coordinate, mm: finite and within ±:data:`~.limits.MAX_LENGTH_MM`."""
    return check_number(
        value, where, positive=positive, nonnegative=nonnegative, bound=MAX_LENGTH_MM, unit="mm"
    )


def check_vector(value, where, length=3, *, bound=None, unit=""):
    """A list or tuple of ``length`` finite numbers (each within ±``bound``), as floats."""
    if not isinstance(value, list | tuple) or len(value) != length:
        raise InputError(f"{where}: expected a list of {length} numbers, got {value!r}")
    return tuple(
        check_number(v, f"{where}[{i}]", bound=bound, unit=unit) for i, v in enumerate(value)
    )


def check_range(value, where):
    """A ``[min, max]`` pair with min below max, as a tuple."""
    lo, hi = check_vector(value, where, length=2)
    if not lo < hi:
        raise InputError(f"{where}: min must be below max, got [{lo}, {hi}]")
    return lo, hi


def require_key(data, key, where=""):
    """``data[key]`` and its path ``where + key``; ``data`` must be an object holding ``key``."""
    path = f"{where}{key}"
    if not isinstance(data, dict):
        raise InputError(f"{where.rstrip('.') or 'design'}: expected an object")
    if key not in data:
        raise InputError(f"{path}: missing key")
    return data[key], path


def _shown(key):
    """A key as written, or quoted when it is not a plain word (empty, spaces, newlines)."""
    return key if isinstance(key, str) and re.fullmatch(r"[\w-]+", key) else repr(key)


def reject_unknown(data, allowed, where):
    """Fail on keys of ``data`` not in ``allowed``, naming them and the allowed ones."""
    unknown = sorted(set(data) - set(allowed), key=str)
    if unknown:
        raise InputError(
            f"{where}: unknown key(s) {', '.join(map(_shown, unknown))}; "
            f"allowed: {', '.join(allowed)}"
        )


def check_finite_tree(data, where):
    """Refuse a NaN or infinite float anywhere in a JSON-like tree of dicts and lists.

    Parameters
    ----------
    data : object
        E.g. a design's free-form ``predicted`` block.
    where : str
        The block's path, for the message.

    Returns
    -------
    object
        ``data``.
    """
    stack = [(where, data)]
    while stack:
        path, value = stack.pop()
        if isinstance(value, dict):
            stack.extend((f"{path}.{k}", v) for k, v in value.items())
        elif isinstance(value, list | tuple):
            stack.extend((f"{path}[{i}]", v) for i, v in enumerate(value))
        elif isinstance(value, float) and not math.isfinite(value):
            raise InputError(f"{path}: must be finite, got {value} (JSON has no NaN or infinity)")
    return data
