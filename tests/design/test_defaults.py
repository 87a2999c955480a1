"""The built-in design, and a design as the library calls take it."""

import pytest


def test_default_design_resembles_the_paper_unit(design):
    assert design.mechanics.unit_diameter_mm == 22
    assert design.mechanics.bearing_bore_mm == 6 and design.mechanics.bearing_od_mm == 14
    assert design.workspace.pitch_deg == (-15, 15) and design.workspace.roll_deg == (-15, 15)
    assert design.workspace.step_deg == 0.1
    assert [s.model for s in design.sensors] == ["NJL5901R-2", "NJL5901R-2"]
    assert design.reflector.inner_radius_mm > design.mechanics.bearing_od_mm / 2


def test_as_design_takes_a_design_its_file_or_none(tmp_path):
    from reflector_opt.design import Design, as_design, default_design, load_design
    from reflector_opt.util.errors import InputError

    design = default_design()
    assert as_design(design) is design
    assert as_design(None) == default_design()
    path = tmp_path / "design.json"
    design.save(path)
    assert as_design(path) == load_design(path) and isinstance(as_design(str(path)), Design)
    with pytest.raises(InputError, match=r"missing\.json"):
        as_design(tmp_path / "missing.json")
