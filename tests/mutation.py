"""Hypothesis strategies of the readers' property tests: valid documents, mutated.

A document is mutated one to four times: a key or item is replaced with NaN, infinities,
huge, negative and fractional numbers, wrong types or nested junk, a number is scaled to
absurd sizes, a key is deleted, or an unknown key or item is added. :func:`mutation` also
gives the keys it touched, and :func:`check_contract` asserts what a reader owes any
document: refused with one line naming a touched key, or accepted with finite values that
survive a round trip.
"""

import copy
import dataclasses
import enum
import math
import re
from pathlib import Path

import msgspec
import numpy as np
from hypothesis import strategies as st

from reflector_opt.util._errors import InputError

ODD_VALUES = (
    math.nan,
    math.inf,
    -math.inf,
    1e308,
    -1e308,
    10**400,
    -(10**30),
    0,
    -1,
    -0.0,
    2.5,
    1e-320,
    True,
    False,
    None,
    "",
    "NJL5901R-2",
    [],
    {},
    [1, 2],
    [1.0, 2.0, 3.0],
    [[1, 2], 3],
    {"a": 1},
)

JUNK = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=4),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=4), inner),
    max_leaves=12,
)
VALUES = st.one_of(st.sampled_from(ODD_VALUES), st.floats(), st.integers(), JUNK)


def places(node, path=()):
    """Every (container, key, path of the key from the root) of a JSON-like tree."""
    stack = [(node, path)]
    while stack:
        current, where = stack.pop()
        keys = current.keys() if isinstance(current, dict) else range(len(current))
        for key in list(keys):
            yield current, key, (*where, key)
            if isinstance(current[key], dict | list):
                stack.append((current[key], (*where, key)))


def _mutate_once(draw, doc):
    """One edit of ``doc`` in place; the path of the key or item it touched, or None."""
    spots = list(places(doc))
    if not spots:
        return None
    container, key, path = draw(st.sampled_from(spots))
    action = draw(st.sampled_from(("replace", "replace", "scale", "delete", "add")))
    value = container[key]
    if action == "replace":
        container[key] = copy.deepcopy(draw(VALUES))
    elif action == "scale" and isinstance(value, int | float) and not isinstance(value, bool):
        factor = draw(st.sampled_from((-1.0, 0.0, 1e-9, 1e3, 1e9, 1e300)))
        try:
            container[key] = value * factor
        except OverflowError:  # an integer beyond any float: so is its product, or it is 0
            sign = math.copysign(1.0, factor) * (1.0 if value > 0 else -1.0)
            container[key] = 0.0 if factor == 0.0 else math.copysign(math.inf, sign)
    elif action == "delete" and isinstance(container, dict):
        del container[key]
    elif action == "add" and isinstance(container, dict):
        new = draw(st.text(min_size=1, max_size=6))
        container[new] = copy.deepcopy(draw(VALUES))
        return (*path[:-1], new)
    elif action == "add":
        container.append(copy.deepcopy(draw(VALUES)))
    else:
        return None  # a no-op: scaling a non-number, deleting a list item
    return path


@st.composite
def mutation(draw, *bases):
    """One of ``bases`` (JSON-like) mutated one to four times, and the paths it touched."""
    doc = copy.deepcopy(draw(st.sampled_from(bases)))
    touched = [_mutate_once(draw, doc) for _ in range(draw(st.integers(1, 4)))]
    return doc, [p for p in touched if p is not None]


#: The values every key of a document is replaced by, one at a time, by :func:`single_edits`.
SWEEP_VALUES = (math.nan, math.inf, -1e308, -1, 0, "", None, [], {"a": 1}, True)


def single_edits(base):
    """Every document that differs from ``base`` in one key or item, deleted or replaced by one
    of :data:`SWEEP_VALUES`, with the path it touched: a deterministic sweep beside the random
    mutations, so no single bad value depends on a draw to be found."""
    for index, (_, key, path) in enumerate(list(places(base))):
        for value in (*SWEEP_VALUES, "delete"):
            doc = copy.deepcopy(base)
            container, _, _ = list(places(doc))[index]
            if value != "delete":
                container[key] = copy.deepcopy(value)
            elif isinstance(container, dict):
                del container[key]
            else:
                continue
            yield doc, [path]


@st.composite
def mutated(draw, *bases):
    """One of ``bases`` (JSON-like), mutated one to four times."""
    return draw(mutation(*bases))[0]


def finite_values(value, where="value"):
    """Assert every number reachable in ``value`` (dataclasses, objects' attributes, mappings,
    sequences, arrays) is finite."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        for field in dataclasses.fields(value):
            finite_values(getattr(value, field.name), f"{where}.{field.name}")
    elif isinstance(value, msgspec.Struct):  # a typed record: its JSON, unset fields left out
        finite_values(msgspec.to_builtins(value, enc_hook=lambda v: v.item()), where)
    elif isinstance(value, dict):
        for key, item in value.items():
            finite_values(item, f"{where}.{key}")
    elif isinstance(value, list | tuple):
        for i, item in enumerate(value):
            finite_values(item, f"{where}[{i}]")
    elif isinstance(value, np.ndarray) and value.dtype.kind in "fc":
        assert np.all(np.isfinite(value)), where
    elif isinstance(value, float | np.floating):
        assert math.isfinite(value), f"{where} = {value}"
    elif hasattr(value, "__dict__") and not isinstance(value, enum.Enum | Path):
        for name, item in vars(value).items():
            finite_values(item, f"{where}.{name}")
    else:
        assert isinstance(value, str | int | bool | type(None) | enum.Enum | Path | np.ndarray)


def names_a_touched_key(message, touched):
    """True if a one-line ``message`` names a key on one of the ``touched`` paths (the key itself,
    a table holding it, or a key of the table it was added to or deleted from)."""
    names = {k for path in touched for k in path if isinstance(k, str)}

    def plain(text):  # escapes and unprintable characters out: readers show keys either way
        text = re.sub(r"\\(x[0-9a-fA-F]{2}|u[0-9a-fA-F]{4}|U[0-9a-fA-F]{8}|.)", "", text)
        return "".join(c for c in text if c.isprintable())

    def named(name):
        if not name:
            return "''" in message or '""' in message
        if any(form in message for form in (name, repr(name)[1:-1])):
            return True
        return not plain(name) or plain(name) in plain(message)

    return not names or any(named(n) for n in names)


def check_contract(read, document, touched, round_trip=None, relations=()):
    """Read ``document`` and assert the readers' contract; the result, or None if refused.

    Refused: an :class:`~reflector_opt.util._errors.InputError` of one line that names a
    touched key, or, for a check of a relation between keys, begins with one of the
    ``relations`` the reader names its relation checks by. Accepted: every number of the
    result finite, and ``round_trip(result)`` (write it out and read it back) equal to the
    result. Any other exception propagates.
    """
    try:
        result = read(document)
    except InputError as exc:
        message = str(exc)
        assert message and "\n" not in message.strip(), message
        relation = message.startswith(tuple(relations))
        assert relation or names_a_touched_key(message, touched), (message, touched)
        return None
    finite_values(result)
    if round_trip is not None:
        assert round_trip(result) == result
    return result
