"""Gathering a batch from AS_BUILT.json files: what belongs together, and what is refused."""

import copy
import json

import numpy as np
import pytest

from reflector_opt.asbuilt._asbuiltfile import identification_to_dict
from reflector_opt.asbuilt._batch import Batch, check_design, geometry_names, load_batch
from reflector_opt.asbuilt._pooling import pool
from reflector_opt.design import default_design
from reflector_opt.util._errors import InputError
from tests.asbuilt.printloop import drawn_design, printed


@pytest.fixture(scope="module")
def document():
    _, result = printed("strong")
    return identification_to_dict(result, "cal.csv", batch="B1")


def _split(document, tmp_path):
    """Two files, the first two units and the rest."""
    paths = []
    for k, units in enumerate((document["units"][:2], document["units"][2:])):
        part = copy.deepcopy(document)
        part["units"] = units
        path = tmp_path / f"part{k}.json"
        path.write_text(json.dumps(part))
        paths.append(path)
    return paths


def test_files_of_one_batch_pool_as_one_identification(document, tmp_path):
    whole = tmp_path / "whole.json"
    whole.write_text(json.dumps(document, indent=1))
    one = load_batch([whole])
    two = load_batch(_split(document, tmp_path))
    assert one.labels == two.labels == ("1", "2", "3", "4")
    assert one.names == geometry_names(2) and one.batch == "B1"
    assert np.array_equal(one.deviations, two.deviations)
    assert [s.units for s in two.sources] == [("1", "2"), ("3", "4")]
    # a file is known by its content, not its spelling
    _, result = printed("strong")
    memory = Batch.from_identification(result, "cal.csv", batch="B1")
    assert memory.sources[0].digest == one.sources[0].digest
    a, b = pool(one), pool(two)
    assert [d.estimate for d in a.directions] == pytest.approx([d.estimate for d in b.directions])


def _mutated(document, tmp_path, change):
    first, second = _split(document, tmp_path)
    data = json.loads(second.read_text())
    change(data)
    second.write_text(json.dumps(data))
    return [first, second]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            lambda d: d["design"]["reflector"].update(radius_mm=9.2),
            r"identified against another design than .*part0.json \(design.reflector.radius_mm: "
            r"9.0 against 9.2\)",
        ),
        (lambda d: d.update(batch="B2"), "batch 'B2', but .*part0.json: batch 'B1'"),
        (lambda d: d.pop("batch"), "no batch recorded, but .*part0.json: batch 'B1'"),
        (lambda d: d["units"][0].update(unit="1"), "unit '1' is also in .*part0.json"),
        (
            lambda d: d["prior"]["surface_std"].update(reflectance=0.1),
            "identified with another prior",
        ),
    ],
)
def test_files_that_do_not_belong_together_are_refused(document, tmp_path, change, message):
    with pytest.raises(InputError, match=message):
        load_batch(_mutated(document, tmp_path, change))


def test_the_same_identification_twice_is_refused(document, tmp_path):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    a.write_text(json.dumps(document))
    b.write_text(json.dumps(document, indent=2))
    with pytest.raises(InputError, match=r"the same identification as .*a.json, given twice"):
        load_batch([a, b])
    with pytest.raises(InputError, match="no as-built file"):
        load_batch([])


def test_another_design_to_correct_is_refused(document, tmp_path):
    path = tmp_path / "a.json"
    path.write_text(json.dumps(document))
    batch = load_batch([path])
    check_design(batch, drawn_design().replace(predicted={"objective_deg": 0.1}))
    with pytest.raises(InputError, match=r"is not the design the units of .*a.json were printed"):
        check_design(batch, default_design(), "d.json")


@pytest.mark.parametrize("recorded_as", ["matrix", "std"])
def test_a_recorded_model_form_term_is_kept_apart_and_weighed_once(document, recorded_as):
    from reflector_opt.asbuilt._batch import _from_documents

    data = copy.deepcopy(document)
    for unit in data["units"]:
        names = unit["covariance"]["names"]
        k = names.index("reflector_centre_z_mm")
        unit["covariance"]["matrix"][k][k] += 0.02**2
        for name, row in unit["parameters"].items():
            row["model_form_std"] = 0.02 if name == "reflector_centre_z_mm" else 0.0
        form = np.zeros((len(names), len(names)))
        form[k, k] = 0.02**2
        unit["covariance"]["model_form"] = form.tolist() if recorded_as == "matrix" else None
    plain = _from_documents([(None, document)])
    recorded = _from_documents([(None, data)])
    j = recorded.names.index("reflector_centre_z_mm")
    assert np.allclose(recorded.covariances, plain.covariances, atol=1e-12)
    assert np.allclose(recorded.systematic[:, j, j], 0.02**2)
    a, b = pool(plain), pool(recorded)
    assert a.model_form == () and b.model_form == ("the identification files",)
    # the term is common to the units: it does not shrink with their number
    worst = max(b.directions, key=lambda d: abs(d.weights[j]))
    assert worst.model_form >= abs(worst.weights[j]) * 0.02 / recorded.prior_std[j] - 1e-9
