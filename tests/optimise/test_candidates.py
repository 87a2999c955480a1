"""Candidate designs carry the problem's reflector surface."""

from reflector_opt.optimiser import Problem


def test_candidates_carry_the_problems_surface():
    from reflector_opt.model._surface import get_material

    problem = Problem(surface=get_material("polished"))
    values = {name: lo for name, (lo, hi) in problem.search_bounds.items()}
    values["gap_mm"] = 1.5
    design = problem.design(values, checked=False)
    assert design.reflector.specular_fraction == 1.0
    assert problem.baseline_design().reflector.specular_fraction == 1.0
