"""The bearing catalogue, a design naming a bearing or describing its joint, and the tilt a
workspace asks."""

import math
import re

import numpy as np
import pytest

from reflector_opt.design import Mechanics, Workspace, default_design, load_design
from reflector_opt.design import _bearings as bearings
from reflector_opt.design._bearings import (
    FIGURES,
    JOINT_KEYS,
    check_tilt,
    design_bearing,
    get_bearing,
    load_bearings,
    ring_tilt_deg,
    shipped_bearings,
    stop_tilt_deg,
    workspace_tilt_deg,
)
from reflector_opt.design._designfile import design_to_dict
from reflector_opt.design._parts import design_parameters
from reflector_opt.model._geometry import rotation_x, rotation_y
from reflector_opt.util._errors import InputError


def test_every_shipped_figure_has_its_kind_and_source():
    for bearing in shipped_bearings():
        assert set(bearing.figures) == set(FIGURES)
        for figure in bearing.figures.values():
            assert figure["kind"] in ("published", "derived", "assumed") and figure["source"]


def test_the_ge4e_as_read_from_its_dimension_table():
    ge4 = get_bearing("GE4E")
    assert (ge4.bore_mm, ge4.outer_diameter_mm, ge4.tilt_deg) == (4.0, 12.0, 16.0)
    dimensions = {k: f for k, f in ge4.figures.items() if not k.startswith("clearance")}
    assert {f["kind"] for f in dimensions.values()} == {"published"}


def test_the_ring_edge_tilt_by_hand_and_against_the_published_tilt():
    # B 5, C 3, dk 8: asin(0.625) - asin(0.375) = 38.682° - 22.024° = 16.658°
    assert ring_tilt_deg(5, 3, 8) == pytest.approx(16.658, abs=1e-3)
    assert 16.0 <= ring_tilt_deg(5, 3, 8) < 17.0  # SKF states 16° for the GE 4 E
    with pytest.raises(InputError, match="C < B"):
        ring_tilt_deg(3, 5, 8)


def test_the_workspace_tilt_is_the_angle_of_the_rotated_axis_at_the_corner():
    # independent path: rotate z by Rx(roll)·Ry(pitch) on a grid and take the largest angle
    pitch, roll = np.meshgrid(np.linspace(-15, 15, 31), np.linspace(-10, 10, 21))
    z = (rotation_x(roll) @ rotation_y(pitch))[..., :, 2]
    largest = np.degrees(np.arccos(z[..., 2])).max()
    assert workspace_tilt_deg((-15, 15), (-10, 10)) == pytest.approx(largest, abs=1e-9)
    assert workspace_tilt_deg((-15, 15), (-15, 15)) == pytest.approx(
        math.degrees(math.acos(math.cos(math.radians(15)) ** 2))
    )


def test_a_named_bearing_sets_the_bore_and_outer_diameter_and_is_written():
    """Its dimensions replace any given (a config fills in the defaults 6 and 14)."""
    mechanics = Mechanics.from_dict(
        {"bearing": "GE4E", "unit_diameter_mm": 16, "bearing_od_mm": 14}
    )
    assert (mechanics.bearing_bore_mm, mechanics.bearing_od_mm) == (4.0, 12.0)
    assert mechanics.to_dict()["bearing"] == "GE4E"
    assert Mechanics().to_dict()["bearing"] is None


@pytest.mark.parametrize(
    ("block", "message"),
    [
        ({"bearing": "GE99"}, "unknown bearing 'GE99'"),
        (
            {"bearing": "GE 4 E"},
            r"mechanics\.bearing: unknown bearing 'GE 4 E'; the catalogue has: GE4E, GE6E",
        ),
    ],
)
def test_bad_bearings_are_refused_in_one_line(block, message):
    with pytest.raises(InputError, match=message) as info:
        Mechanics.from_dict(block)
    assert "\n" not in str(info.value)


def test_the_mechanical_stop_by_hand():
    # acos(d/dk) - asin(C/dk): GE 6 E 53.130° - 23.578°, GE 4 E 60° - 22.024°
    assert stop_tilt_deg(6, 4, 10) == pytest.approx(29.552, abs=1e-3)
    assert get_bearing("GE6E").stop_deg == pytest.approx(29.552, abs=1e-3)
    assert get_bearing("GE4E").stop_deg == pytest.approx(37.976, abs=1e-3)
    for bearing in shipped_bearings():  # the stop lies past the rated tilt
        assert bearing.stop_deg > bearing.tilt_deg
    with pytest.raises(InputError, match="needs d, C < dk"):
        stop_tilt_deg(10, 4, 10)


def test_the_stop_limits_the_workspace_and_the_rated_tilt_warns(caplog):
    bearings._warn_past_rated_tilt.cache_clear()  # warned once a process: this test's own
    mechanics = Mechanics(bearing="GE4E")
    with caplog.at_level("WARNING"):
        assert check_tilt(Workspace((-11, 11), (-11, 11)), mechanics) < 16.0
    assert not caplog.records
    with caplog.at_level("WARNING"):  # the paper's ±15° × ±15°: 21.1° at the corner
        assert check_tilt(Workspace(), mechanics) == pytest.approx(21.1, abs=0.05)
    assert "beyond the 16° rated tilt of the bearing GE4E" in caplog.text
    with pytest.raises(InputError, match=r"up to 41.4° .* beyond the 38.0° mechanical stop"):
        check_tilt(Workspace((-30, 30), (-30, 30)), mechanics)
    with caplog.at_level("WARNING"):  # the paper's bearing named: accepted, warned
        assert check_tilt(Workspace(), Mechanics(bearing="GE6E")) == pytest.approx(21.1, abs=0.05)
    assert "beyond the 13° rated tilt of the bearing GE6E" in caplog.text
    # a design that names no bearing is checked against the GE 6 E, whose parts it takes
    assert check_tilt(Workspace(), Mechanics()) == pytest.approx(21.1, abs=0.05)
    with pytest.raises(InputError, match=r"beyond the 29.6° mechanical stop of the bearing GE6E"):
        check_tilt(Workspace((-25, 25), (-25, 25)), Mechanics())
    design = default_design()
    data = design_to_dict(design)
    data["mechanics"]["bearing"] = "GE4E"
    data["workspace"]["pitch_deg"] = [-30.0, 30.0]
    data["workspace"]["roll_deg"] = [-30.0, 30.0]
    with pytest.raises(InputError, match="workspace: pitch"):
        type(design).from_dict(data)


def test_each_bearing_states_its_clearance_classes_in_order():
    for bearing in shipped_bearings():
        c2, normal, c3 = (bearing.clearance_um(g) for g in ("C2", "normal", "C3"))
        assert c2[0] < c2[1] <= normal[1] <= c3[1]
        assert normal == (32.0, 68.0)  # ISO 12240-1, bores up to 12 mm (assumed row)
        assert bearing.figures["clearance_normal_um"]["kind"] == "assumed"


def test_a_catalogue_file_with_a_tilt_beyond_its_rings_is_refused(tmp_path):
    text = (
        'format = "reflector-opt/bearing-catalogue@1"\n[[bearing]]\nname = "X"\n'
        'designation = "X"\nmaker = "m"\nkind = "k"\ndatasheet = "d"\n[bearing.figures]\n'
    )
    figures = {"bore_mm": 4, "outer_diameter_mm": 12, "inner_width_mm": 5}
    figures |= {"outer_width_mm": 3, "ball_diameter_mm": 8, "tilt_deg": 20}
    figures |= {f"clearance_{g}_um": [10, 20] for g in ("c2", "normal", "c3")}
    for key, value in figures.items():
        text += f'{key} = {{ value = {value}, kind = "assumed", source = "s" }}\n'
    path = tmp_path / "b.toml"
    path.write_text(text)
    with pytest.raises(InputError, match=r"bearing\[0\] \(X\)\.figures\.tilt_deg: 20°"):
        load_bearings(path)


# --- a joint the user describes -------------------------------------------------------------


def described(name, **change):
    """A catalogue bearing's own figures as a described joint (its normal class's upper end)."""
    bearing = get_bearing(name)
    joint = {k: bearing.value(k) for k in JOINT_KEYS[:5]}
    return joint | {"clearance_um": bearing.clearance_um("normal")[1]} | change


def test_a_described_joint_takes_the_catalogue_s_stop_and_rated_tilt_formulas():
    # the GE 6 E's own figures (d 6, C 4, dk 10): acos(0.6) - asin(0.4) = 53.130° - 23.578°
    joint = design_bearing(Mechanics(joint=described("GE6E")))
    assert joint.stop_deg == pytest.approx(29.552, abs=1e-3)
    assert joint.stop_deg == get_bearing("GE6E").stop_deg
    # the rated tilt from the rings (B 6): asin(0.6) - asin(0.4) = 36.870° - 23.578°
    assert joint.tilt_deg == pytest.approx(13.292, abs=1e-3)
    assert joint.figures["tilt_deg"]["kind"] == "derived"
    assert {joint.figures[k]["kind"] for k in JOINT_KEYS[:5]} == {"stated"}
    assert "the user's description" in joint.figures["bore_mm"]["source"]
    with pytest.raises(InputError, match=r"29.6° mechanical stop of the joint described in"):
        check_tilt(Workspace((-25, 25), (-25, 25)), Mechanics(joint=described("GE6E")))
    # a stated stop wins: 20° refuses the paper's 21.1° corner, which the derived one accepts
    stated = Mechanics(joint=described("GE6E", stop_deg=20.0))
    assert design_bearing(stated).stop_deg == 20.0
    with pytest.raises(InputError, match=r"up to 21.1° .* beyond the 20.0° mechanical stop"):
        check_tilt(Workspace(), stated)


def test_a_described_joint_sets_the_mechanics_and_the_parts_as_the_named_bearing():
    joint, named = Mechanics(joint=described("GE4E")), Mechanics(bearing="GE4E")
    assert (joint.bearing_bore_mm, joint.bearing_od_mm) == (4.0, 12.0)
    design = default_design()
    params = [design_parameters(None, design.replace(mechanics=m)) for m in (joint, named)]
    assert params[0] == params[1]
    assert params[0].bearing_ball_diameter_mm == 8.0  # the GE 4 E's dk, not the GE 6 E's 10
    assert params[0].bearing_outer_width_mm == 3.0


def test_a_described_joint_round_trips_through_design_json(tmp_path):
    joint = described("GE4E", clearance_um=20, stop_deg=30)
    design = default_design().replace(mechanics=Mechanics(unit_diameter_mm=22, joint=joint))
    design.save(tmp_path / "design.json")
    loaded = load_design(tmp_path / "design.json")
    assert loaded.mechanics == design.mechanics
    assert loaded.mechanics.joint == {k: float(v) for k, v in joint.items()}
    assert design_bearing(loaded.mechanics).figures == design_bearing(design.mechanics).figures


def test_a_design_file_without_a_joint_is_still_read_and_written_as_it_was():
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "examples" / "data" / "design.json"
    design = load_design(path)
    assert design.mechanics.joint is None and design_bearing(design.mechanics).name == "GE6E"
    assert "joint" not in design_to_dict(design)["mechanics"]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"ball_diameter_mm": 15.0}, ".ball_diameter_mm: 15 mm must be between the bore and D"),
        ({"ball_diameter_mm": 6.0}, ".ball_diameter_mm: 6 mm must be between the bore and D"),
        ({"bore_mm": 14.0}, ".bore_mm: 14 mm must be smaller than outer_diameter_mm"),
        ({"inner_width_mm": 11.0}, ".inner_width_mm: 11 mm must be at most ball_diameter_mm"),
        ({"outer_width_mm": 6.0}, ".outer_width_mm: 6 mm must be narrower than inner_width_mm"),
        ({"bore_mm": float("nan")}, ".bore_mm: must be finite"),
        ({"outer_width_mm": -4.0}, ".outer_width_mm: must be positive"),
        ({"bore_mm": 0.006}, ".bore_mm: 0.006 mm (below 0.5 mm) looks like metres"),
        ({"outer_diameter_mm": 1e5}, ".outer_diameter_mm: must be at most 1000 mm"),
        ({"clearance_um": 0.05}, ".clearance_um: 0.05 µm (below 0.5 µm) looks like millimetres"),
        ({"clearance_um": 900.0}, ".clearance_um: must be at most 500 µm"),
        ({"stop_deg": 90.0}, ".stop_deg: must lie in (0, 90)°"),
        ({"stop_deg": 0.0}, ".stop_deg: must lie in (0, 90)°"),
        ({"width_mm": 1.0}, ": unknown key(s) width_mm"),
    ],
)
def test_bad_described_joints_are_refused_naming_the_key(change, message):
    with pytest.raises(InputError, match=re.escape("mechanics.joint" + message)) as info:
        Mechanics(joint=described("GE6E", **change))
    assert "\n" not in str(info.value)


def test_a_named_bearing_and_a_described_joint_at_once_are_refused():
    with pytest.raises(InputError, match=r"mechanics\.joint: a joint is described and a bearing"):
        Mechanics.from_dict({"bearing": "GE4E", "joint": described("GE4E")})
