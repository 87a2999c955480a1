"""Hypothesis strategies of the readers' property tests: valid documents, mutated.

A document is mutated one to four times: a key or item is replaced with NaN, infinities,
huge, negative and fractional numbers, wrong types or nested junk, a number is scaled to
absurd sizes, a key is deleted, or an unknown key or item is added.
"""

import copy
import math

from hypothesis import strategies as st

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


def places(node):
    """Every (container, key) of a JSON-like tree."""
    stack = [node]
    while stack:
        current = stack.pop()
        keys = current.keys() if isinstance(current, dict) else range(len(current))
        for key in list(keys):
            yield current, key
            if isinstance(current[key], dict | list):
                stack.append(current[key])


@st.composite
def mutated(draw, *bases):
    """One of ``bases`` (JSON-like), mutated one to four times."""
    doc = copy.deepcopy(draw(st.sampled_from(bases)))
    for _ in range(draw(st.integers(1, 4))):
        spots = list(places(doc))
        if not spots:
            break
        container, key = draw(st.sampled_from(spots))
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
            container[draw(st.text(max_size=6))] = copy.deepcopy(draw(VALUES))
        elif action == "add":
            container.append(copy.deepcopy(draw(VALUES)))
    return doc
