"""The design.json round trip: format, public keys, reading and atomic writing."""

import json

import pytest

from reflector_opt.design._design import Design, load_design
from reflector_opt.design._designfile import FORMAT, first_difference
from reflector_opt.util._errors import InputError


def test_json_round_trip(tmp_path, design):
    path = tmp_path / "design.json"
    design.save(path)
    data = json.loads(path.read_text())
    assert data["format"] == FORMAT
    # the public contract keys
    assert data["reflector"]["radius_mm"] == design.reflector.radius_mm
    assert data["reflector"]["centre_mm"] == list(design.reflector.centre_mm)
    assert data["sensors"][1]["position_mm"] == list(design.sensors[1].position_mm)
    assert data["workspace"]["pitch_deg"] == [-15.0, 15.0]
    assert data["workspace"]["roll_deg"] == [-15.0, 15.0]
    assert load_design(path) == design


def test_load_design_reports_unreadable_and_malformed_files(tmp_path):
    with pytest.raises(InputError, match="cannot read"):
        load_design(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{ not json")
    with pytest.raises(InputError, match="not valid JSON"):
        load_design(bad)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[]", "design: expected a JSON object"),
        ("{}", "reflector: missing key"),
        ('{"reflector": 1, "sensors": [], "workspace": {}}', "reflector: expected"),
    ],
)
def test_a_bad_document_is_named_by_its_file_as_every_reader_does(tmp_path, text, message):
    """Commands reading a design beside other files (calibrate --design, fit-sensor
    --design) must say which file is at fault: the message starts with its path."""
    path = tmp_path / "lab-design.json"
    path.write_text(text)
    with pytest.raises(InputError) as error:
        load_design(path)
    assert str(error.value).startswith(f"{path}: {message}")


def test_save_is_atomic(tmp_path, design, monkeypatch):
    """A failure while writing leaves the previous file whole and no temporary behind."""
    path = tmp_path / "design.json"
    design.save(path)
    before = path.read_text()
    monkeypatch.setattr(Design, "to_dict", lambda self: {"bad": float("nan")})
    with pytest.raises(ValueError):
        design.save(path)
    assert path.read_text() == before
    assert [p.name for p in tmp_path.iterdir()] == ["design.json"]


def test_saved_files_get_ordinary_permissions(tmp_path, design):
    import os

    path = tmp_path / "design.json"
    design.save(path)
    mask = os.umask(0o022)
    os.umask(mask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~mask


def test_a_design_without_a_surface_reads_as_the_mirror_it_was_made_for(tmp_path, design, caplog):
    data = design.to_dict()
    del data["reflector"]["specular_fraction"]
    path = tmp_path / "old.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    with caplog.at_level("WARNING"):
        loaded = load_design(path)
    assert loaded.reflector.specular_fraction == 1.0
    assert "specular_fraction is absent: read as 1 (a mirror)" in caplog.text
    assert design.reflector.specular_fraction == 0.05  # the default: white SLA resin


@pytest.mark.parametrize(
    ("block", "key", "value", "message"),
    [
        (
            "mechanics",
            "n_units",
            2.5,
            "mechanics.n_units: expected a whole number from 1 to 1000, got 2.5",
        ),
        ("reflector", "inner_radius_mm", 20.0, "the inner surface lies outside the sphere"),
    ],
    ids=["a part", "the whole design"],
)
def test_a_refused_design_without_a_surface_warns_of_nothing(
    tmp_path, design, caplog, block, key, value, message
):
    """The 'read as 1 (a mirror)' warning came before the error of every such refusal."""
    data = design.to_dict()
    del data["reflector"]["specular_fraction"]
    data[block][key] = value
    path = tmp_path / "old.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    with caplog.at_level("WARNING"), pytest.raises(InputError, match=message):
        load_design(path)
    assert caplog.records == []


def test_first_difference_names_the_path_and_both_values():
    mine = {"a": 1.0, "sensors": [{"x": [1.0, 2.0]}, {"x": [3.0, 4.0]}], "skip": 1}
    theirs = {"a": 1.0, "sensors": [{"x": [1.0, 2.0]}, {"x": [3.0, 4.5]}], "skip": 2}
    assert first_difference(mine, mine) is None
    assert first_difference(mine, theirs) == ("sensors[1].x[1]", 4.0, 4.5)
    assert first_difference(mine, {**mine, "skip": 2}, ignored={("skip",)}) is None
    assert first_difference({"b": 1.0}, {}) == ("b", 1.0, None)
    close = {"a": 1.0 + 1e-12}
    assert first_difference({"a": 1.0}, close) == ("a", 1.0, 1.0 + 1e-12)
    assert first_difference({"a": 1.0}, close, rel_tol=1e-9) is None
    assert first_difference({"a": [1, 2]}, {"a": [1]}) == ("a", [1, 2], [1])
