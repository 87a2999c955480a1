"""The bearing catalogue, a design naming a bearing, and the tilt a workspace asks."""

import math

import numpy as np
import pytest

from reflector_opt.design import Mechanics, Workspace, default_design
from reflector_opt.design.bearings import (
    FIGURES,
    check_tilt,
    get_bearing,
    load_bearings,
    ring_tilt_deg,
    shipped_bearings,
    workspace_tilt_deg,
)
from reflector_opt.design.designfile import design_to_dict
from reflector_opt.model.geometry import rotation_x, rotation_y
from reflector_opt.util.errors import InputError


def test_every_shipped_figure_has_its_kind_and_source():
    for bearing in shipped_bearings():
        assert set(bearing.figures) == set(FIGURES)
        for figure in bearing.figures.values():
            assert figure["kind"] in ("published", "derived", "assumed") and figure["source"]


def test_the_ge4e_as_read_from_its_dimension_table():
    ge4 = get_bearing("GE4E")
    assert (ge4.bore_mm, ge4.outer_diameter_mm, ge4.tilt_deg) == (4.0, 12.0, 16.0)
    assert {f["kind"] for f in ge4.figures.values()} == {"published"}


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
        ({"bearing": "GE 4 E"}, "mechanics.bearing: expected a bearing name"),
    ],
)
def test_bad_bearings_are_refused_in_one_line(block, message):
    with pytest.raises(InputError, match=message) as info:
        Mechanics.from_dict(block)
    assert "\n" not in str(info.value)


def test_the_bearing_tilt_limits_the_workspace():
    mechanics = Mechanics(bearing="GE4E")
    assert check_tilt(Workspace((-11, 11), (-11, 11)), mechanics) < 16.0
    with pytest.raises(InputError, match=r"up to 21.1° .* beyond the 16° the bearing GE4E"):
        check_tilt(Workspace(), mechanics)
    assert check_tilt(Workspace(), Mechanics()) is None
    design = default_design()
    data = design_to_dict(design)
    data["mechanics"]["bearing"] = "GE4E"
    with pytest.raises(InputError, match="workspace: pitch"):
        type(design).from_dict(data)


def test_a_catalogue_file_with_a_tilt_beyond_its_rings_is_refused(tmp_path):
    text = (
        'format = "reflector-opt/bearing-catalogue@1"\n[[bearing]]\nname = "X"\n'
        'designation = "X"\nmaker = "m"\nkind = "k"\ndatasheet = "d"\n[bearing.figures]\n'
    )
    figures = {"bore_mm": 4, "outer_diameter_mm": 12, "inner_width_mm": 5}
    figures |= {"outer_width_mm": 3, "ball_diameter_mm": 8, "tilt_deg": 20}
    for key, value in figures.items():
        text += f'{key} = {{ value = {value}, kind = "assumed", source = "s" }}\n'
    path = tmp_path / "b.toml"
    path.write_text(text)
    with pytest.raises(InputError, match=r"bearing\[0\] \(X\)\.figures\.tilt_deg: 20°"):
        load_bearings(path)
