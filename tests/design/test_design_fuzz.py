"""Random and mutated design.json documents load to a valid design or raise InputError.

Starting from the default design's document (and one with its own sensor model and measured
curve), keys are replaced with NaN, infinities, huge, negative and fractional numbers, wrong
types and nested junk, deleted, or joined by unknown keys. Whatever the document, reading it
(from a dict or from a file) gives a :class:`Design` or an
:class:`~reflector_opt.util.errors.InputError`; never another exception.
"""

import copy
import json

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

from reflector_opt.design import Design, default_design, load_design
from reflector_opt.model.sensors import NJL5901R_2
from reflector_opt.util.errors import InputError
from tests.mutation import JUNK, mutated


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
@given(doc=mutated(*BASES))
def test_any_document_loads_or_is_an_input_error(folder, doc):
    _outcome(lambda: Design.from_dict(copy.deepcopy(doc)))
    path = folder / "design.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    _outcome(lambda: load_design(path))


@settings(max_examples=60, deadline=None)
@given(JUNK)
def test_any_json_value_loads_or_is_an_input_error(value):
    _outcome(lambda: Design.from_dict(value))
