"""Random and mutated design.json documents load to a valid design or raise InputError.

Starting from the default design's document (and one with its own sensor model and measured
curve), keys are replaced with NaN, infinities, huge, negative and fractional numbers, wrong
types and nested junk, deleted, or joined by unknown keys. Whatever the document, reading it
(from a dict or from a file) gives a :class:`Design` or an
:class:`~reflector_opt.util.errors.InputError`; never another exception.
"""

import copy
import json
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from reflector_opt.design import Design, default_design, load_design
from reflector_opt.model.sensors import NJL5901R_2
from reflector_opt.util.errors import InputError


def _with_own_model():
    design = default_design()
    d = np.linspace(0.4, 3.4, 7)
    model = NJL5901R_2.to_dict()
    model["name"] = "measured"
    model["measured_curve"] = {
        "distance_mm": d.tolist(),
        "volts": NJL5901R_2.output_voltage(NJL5901R_2.flat_coupling(d, 0.9)).tolist(),
        "reflectance": 0.9,
        "specular_fraction": 1.0,
    }
    data = design.to_dict()
    data["sensor_models"] = {"measured": model}
    for sensor in data["sensors"]:
        sensor["model"] = "measured"
    data["predicted"] = {"metrics": {"rms_deg": [0.1, 0.2], "note": "x"}}
    return data


BASES = (default_design().to_dict(), _with_own_model())

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


def _places(node):
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
def documents(draw):
    doc = copy.deepcopy(draw(st.sampled_from(BASES)))
    for _ in range(draw(st.integers(1, 4))):
        places = list(_places(doc))
        if not places:
            break
        container, key = draw(st.sampled_from(places))
        action = draw(st.sampled_from(("replace", "replace", "scale", "delete", "add")))
        value = container[key]
        if action == "replace":
            container[key] = copy.deepcopy(draw(VALUES))
        elif action == "scale" and isinstance(value, int | float) and not isinstance(value, bool):
            factor = draw(st.sampled_from((-1.0, 0.0, 1e-9, 1e3, 1e9, 1e300)))
            try:
                container[key] = value * factor
            except OverflowError:  # an integer beyond any float: scaled up, it is infinite
                container[key] = math.copysign(math.inf, value * math.copysign(1.0, factor))
        elif action == "delete" and isinstance(container, dict):
            del container[key]
        elif action == "add" and isinstance(container, dict):
            container[draw(st.text(max_size=6))] = copy.deepcopy(draw(VALUES))
        elif action == "add":
            container.append(copy.deepcopy(draw(VALUES)))
    return doc


def _outcome(load):
    try:
        design = load()
    except InputError:
        return None
    assert isinstance(design, Design)
    json.dumps(design.to_dict(), allow_nan=False)  # a loaded design can be saved
    return design


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz")


@settings(max_examples=250, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(doc=documents())
def test_any_document_loads_or_is_an_input_error(folder, doc):
    _outcome(lambda: Design.from_dict(copy.deepcopy(doc)))
    path = folder / "design.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    _outcome(lambda: load_design(path))


@settings(max_examples=60, deadline=None)
@given(JUNK)
def test_any_json_value_loads_or_is_an_input_error(value):
    _outcome(lambda: Design.from_dict(value))
