"""Random and mutated design.json documents load to a valid design or raise InputError.

Starting from the default design's document (and one with its own sensor model and measured
curve), keys are replaced with NaN, infinities, huge, negative and fractional numbers, wrong
types and nested junk, deleted, or joined by unknown keys. Whatever the document, reading it
(from a dict or from a file) gives a :class:`Design` that saves and loads to the same
document with finite numbers, or an :class:`~reflector_opt.util._errors.InputError` of one line
naming a key the mutation touched (tests/mutation.py ``check_contract``); never another
exception, and the file and the dict are read alike.
"""

import copy
import json

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

from reflector_opt.design import Design, default_design, load_design
from reflector_opt.model._sensors import NJL5901R_2
from tests.mutation import JUNK, check_contract, mutation, single_edits


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


#: Checks of a relation between keys, named by the key that refers: a sensor naming a model
#: that ``sensor_models`` (deleted or replaced) no longer holds.
RELATIONS = ("sensor 'S1'.model: unknown sensor preset",)


def _round_trip(design):
    """Save the design and load it again: the same document (and valid JSON, finite numbers)."""
    document = json.loads(json.dumps(design.to_dict(), allow_nan=False))
    assert Design.from_dict(document).to_dict() == design.to_dict()
    return design


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz")


@pytest.mark.parametrize("base", range(len(BASES)))
def test_the_valid_documents_load(folder, base):
    assert isinstance(check_contract(Design.from_dict, copy.deepcopy(BASES[base]), []), Design)
    path = folder / "design.json"
    path.write_text(json.dumps(BASES[base]), encoding="utf-8")
    assert isinstance(check_contract(lambda p: load_design(p), path, [], _round_trip), Design)


@settings(max_examples=250, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutation(*BASES))
def test_a_mutated_document_is_refused_naming_its_key_or_loads_and_round_trips(folder, case):
    doc, touched = case
    from_dict = check_contract(
        Design.from_dict, copy.deepcopy(doc), touched, _round_trip, RELATIONS
    )
    path = folder / "design.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    from_file = check_contract(load_design, path, touched, _round_trip, RELATIONS)
    assert (from_dict is None) == (from_file is None)  # the file and the dict are read alike
    if from_dict is not None:
        assert from_dict.to_dict() == from_file.to_dict()


@pytest.mark.parametrize("base", range(len(BASES)))
def test_every_single_bad_value_is_refused_naming_its_key_or_loads(base):
    for edited, touched in single_edits(BASES[base]):
        check_contract(Design.from_dict, edited, touched, _round_trip, RELATIONS)


@settings(max_examples=60, deadline=None)
@given(JUNK)
def test_any_json_value_is_refused_in_one_line_or_loads(value):
    check_contract(Design.from_dict, value, [], _round_trip)
