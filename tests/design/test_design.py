"""The design object: validation that names the field, and the design.json round trip."""

import json
import math

import pytest

from reflector_opt.design.design import FORMAT, Design, default_design, load_design
from reflector_opt.util.errors import InputError


def _document(**changes):
    data = default_design().to_dict()
    for path, value in changes.items():
        keys = path.split(".")
        target = data
        for key in keys[:-1]:
            target = target[int(key)] if isinstance(target, list) else target[key]
        last = keys[-1]
        if value is KeyError:
            del target[last]
        elif isinstance(target, list):
            target[int(last)] = value
        else:
            target[last] = value
    return data


def test_default_design_resembles_the_paper_unit(design):
    assert design.mechanics.unit_diameter_mm == 22
    assert design.mechanics.bearing_bore_mm == 6 and design.mechanics.bearing_od_mm == 14
    assert design.workspace.pitch_deg == (-15, 15) and design.workspace.roll_deg == (-15, 15)
    assert design.workspace.step_deg == 0.1
    assert [s.model for s in design.sensors] == ["NJL5901R-2", "NJL5901R-2"]
    assert design.reflector.inner_radius_mm > design.mechanics.bearing_od_mm / 2


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


def test_workspace_grid_is_the_paper_protocol(design):
    pitch, roll = design.workspace.grid()
    assert pitch.shape == (301, 1) and roll.shape == (1, 301)  # 90,601 poses
    assert pitch[0, 0] == -15 and roll[0, -1] == 15
    assert math.isclose(pitch[1, 0] - pitch[0, 0], 0.1)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"reflector.radius_mm": 0}, r"reflector\.radius_mm: must be positive"),
        ({"reflector.radius_mm": -3.0}, r"reflector\.radius_mm: must be positive"),
        (
            {"reflector.centre_mm": [0, float("nan"), 0]},
            r"reflector\.centre_mm\[1\]: must be finite",
        ),
        ({"reflector.centre_mm": [0, 0]}, r"reflector\.centre_mm: expected a list of 3"),
        ({"reflector.radius_mm": KeyError}, r"reflector\.radius_mm: missing key"),
        ({"sensors.0.position_mm": KeyError}, r"sensors\[0\]\.position_mm: missing key"),
        ({"sensors.1.model": "NOPE-1"}, r"sensor 'S2'\.model: unknown sensor preset 'NOPE-1'"),
        ({"sensors.0.position_mm": [8.0, 0, 0]}, r"S1 would lie inside the reflector sphere"),
        ({"sensors.0.axis": [0, 0, 0]}, r"axis: must not be the zero vector"),
        ({"workspace.pitch_deg": [15, -15]}, r"workspace\.pitch_deg: min must be below max"),
        ({"workspace.step_deg": 0}, r"workspace\.step_deg: must be positive"),
        ({"noise.sigma_v": -1e-3}, r"noise\.sigma_v: must not be negative"),
        ({"noise.adc_bits": 10.5}, r"noise\.adc_bits: must be a whole number"),
        ({"mechanics.bearing_bore_mm": 20}, r"bearing_bore_mm: must be smaller"),
        ({"reflector.colour": "white"}, r"reflector: unknown key\(s\) colour"),
        ({"format": "reflector-opt/design@9"}, r"format: expected"),
        ({"sensors": []}, r"sensors: a unit needs at least two sensors"),
    ],
)
def test_bad_designs_name_the_field(changes, message):
    with pytest.raises(InputError, match=message):
        Design.from_dict(_document(**changes))


def test_load_design_reports_unreadable_and_malformed_files(tmp_path):
    with pytest.raises(InputError, match="cannot read"):
        load_design(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{ not json")
    with pytest.raises(InputError, match="not valid JSON"):
        load_design(bad)


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
