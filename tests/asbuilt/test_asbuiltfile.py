"""The AS_BUILT.json file (asbuilt.asbuiltfile): written and read back, recognised, refused.

The identification is the print loop's batch of four units (tests/asbuilt/printloop.py,
cached: the batch tests identify the same one)."""

import json

import numpy as np
import pytest

from reflector_opt.asbuilt._asbuiltfile import (
    AS_BUILT_FORMAT,
    check_batch_name,
    is_as_built_file,
    load_as_built,
    save_as_built,
)
from reflector_opt.util._errors import InputError
from tests.asbuilt.printloop import drawn_design, printed


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    _, result = printed("strong")
    path = tmp_path_factory.mktemp("asbuilt") / "AS_BUILT.json"
    save_as_built(result, path, source="cal.csv", batch="B1")
    return result, path


def test_a_written_file_reads_back_as_the_identification(written):
    result, path = written
    assert is_as_built_file(path)
    found = load_as_built(path)
    assert found.design == drawn_design() and found.batch == "B1"
    assert found.document["format"] == AS_BUILT_FORMAT
    assert len(found.units) == 4
    for u, unit in enumerate(found.units):
        design, mismatch = result.as_built(u)
        assert unit["as_built"].reflector.radius_mm == pytest.approx(design.reflector.radius_mm)
        np.testing.assert_allclose(
            unit["as_built"].reflector.centre_mm, design.reflector.centre_mm, atol=1e-12
        )
        np.testing.assert_allclose(unit["read_out"].gain, mismatch.gain, rtol=1e-12)
        np.testing.assert_allclose(unit["covariance"]["matrix"], result.unit_covariance(u))


def test_other_files_are_not_as_built_files(tmp_path):
    other = tmp_path / "design.json"
    other.write_text(json.dumps({"format": "reflector-opt/design@1"}))
    broken = tmp_path / "broken.json"
    broken.write_text("{")
    assert not is_as_built_file(other) and not is_as_built_file(broken)
    with pytest.raises(InputError, match="format 'reflector-opt/design@1' is not an as-built"):
        load_as_built(other)


def test_a_covariance_of_the_wrong_shape_is_refused_naming_the_key(written, tmp_path):
    _, path = written
    data = json.loads(path.read_text())
    data["units"][1]["covariance"]["matrix"] = [[1.0]]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    with pytest.raises(InputError, match=r"units\[1\]\.covariance\.matrix: a \d+ × \d+ matrix"):
        load_as_built(bad)


@pytest.mark.parametrize("name", ["", " B1", "B1 ", "x" * 201, 7])
def test_a_bad_batch_name_is_refused(name):
    assert check_batch_name(None) is None and check_batch_name("x" * 200) == "x" * 200
    with pytest.raises(InputError, match=r"^batch: expected a name of 1 to 200 characters"):
        check_batch_name(name)
