"""Value checks shared by the parts of a design, with messages that name the field.

Each check takes the value and ``where``, the field's path in ``design.json`` (e.g.
``"reflector.centre_mm"``), and raises :class:`~reflector_opt.util.errors.InputError`
naming that path when the value is wrong.
"""

from __future__ import annotations

import math

from reflector_opt.util.errors import InputError

__all__ = ["check_number", "check_range", "check_vector", "reject_unknown", "require_key"]


def check_number(value, where, *, positive=False, nonnegative=False):
    """A finite number (not a bool), optionally positive or non-negative, as a float."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InputError(f"{where}: expected a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise InputError(f"{where}: must be finite, got {value}")
    if positive and value <= 0:
        raise InputError(f"{where}: must be positive, got {value}")
    if nonnegative and value < 0:
        raise InputError(f"{where}: must not be negative, got {value}")
    return value


def check_vector(value, where, length=3):
    """A list or tuple of ``length`` finite numbers, as a tuple of floats."""
    if not isinstance(value, list | tuple) or len(value) != length:
        raise InputError(f"{where}: expected a list of {length} numbers, got {value!r}")
    return tuple(check_number(v, f"{where}[{i}]") for i, v in enumerate(value))


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


def reject_unknown(data, allowed, where):
    """Fail on keys of ``data`` not in ``allowed``, naming them."""
    unknown = sorted(set(data) - set(allowed))
    if unknown:
        raise InputError(f"{where}: unknown key(s) {', '.join(unknown)}")
