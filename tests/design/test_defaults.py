"""The built-in design, and a design as the library calls take it."""

from dataclasses import replace

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
    from reflector_opt.util._errors import InputError

    design = default_design()
    assert as_design(design) is design
    assert as_design(None) == default_design()
    path = tmp_path / "design.json"
    design.save(path)
    assert as_design(path) == load_design(path) and isinstance(as_design(str(path)), Design)
    with pytest.raises(InputError, match=r"missing\.json"):
        as_design(tmp_path / "missing.json")


def test_the_default_placed_in_a_unit_is_the_optimisers_baseline_and_evaluates_alike():
    """``default_design(like)``: the built-in geometry in another unit (a 20 mm unit on the
    VCNT2020 at ±12°, polished, its own noise), which ``optimise`` compares with
    (``Problem.baseline_design``) and ``evaluate`` of the design it writes (a candidate of the
    same problem) too; in the paper's unit it is the built-in design itself."""
    from reflector_opt.analysis._surface import resolution_against_surface, surface_comparison
    from reflector_opt.design import Mechanics, Noise, Workspace, default_design
    from reflector_opt.model._catalogue import sensor_model
    from reflector_opt.model._surface import get_material
    from reflector_opt.optimiser import Problem

    built_in = default_design()
    assert default_design(built_in) == built_in
    other_geometry = built_in.replace(reflector=replace(built_in.reflector, radius_mm=8.5))
    assert default_design(other_geometry) == built_in  # the geometry is the built-in one
    problem = Problem(
        sensor=sensor_model("VCNT2020"),
        workspace=Workspace((-12.0, 12.0), (-12.0, 12.0), 0.1),
        mechanics=Mechanics(unit_diameter_mm=20.0),
        noise=Noise(sigma_v=0.003),
        surface=get_material("polished"),
    )
    values = {name: lo for name, (lo, _) in problem.search_bounds.items()}
    written = problem.design({**values, "gap_mm": 1.5}, checked=False)
    base = problem.baseline_design()
    assert default_design(written) == base
    assert base.mechanics == problem.mechanics and base.workspace == problem.workspace
    assert base.noise == problem.noise and [s.model for s in base.sensors] == ["VCNT2020"] * 2
    assert base.reflector.specular_fraction == 1.0 == written.reflector.specular_fraction
    assert base.reflector.centre_mm == built_in.reflector.centre_mm
    assert base.positions_mm.tolist() == built_in.positions_mm.tolist()
    # evaluate's column "default design" is this baseline's, not the paper unit's
    rows = surface_comparison(written)["default_design"]
    assert rows == resolution_against_surface(base)
    (paper,) = resolution_against_surface(built_in, fractions=(rows[0]["specular_fraction"],))
    assert abs(rows[0]["worst_deg"] / paper["worst_deg"] - 1) > 0.05
