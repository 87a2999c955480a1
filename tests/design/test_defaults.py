"""The built-in design."""


def test_default_design_resembles_the_paper_unit(design):
    assert design.mechanics.unit_diameter_mm == 22
    assert design.mechanics.bearing_bore_mm == 6 and design.mechanics.bearing_od_mm == 14
    assert design.workspace.pitch_deg == (-15, 15) and design.workspace.roll_deg == (-15, 15)
    assert design.workspace.step_deg == 0.1
    assert [s.model for s in design.sensors] == ["NJL5901R-2", "NJL5901R-2"]
    assert design.reflector.inner_radius_mm > design.mechanics.bearing_od_mm / 2
