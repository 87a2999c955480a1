"""A relaxed distance margin never returns a worse verified design than a stricter one.

A design that meets a margin meets every smaller one, so the best design at a relaxed margin is
at least as good. With no margin the verification's repair of the printed walls used to wander
(white resin 0.0896° against 0.0885° at the default 0.1 mm, polished 0.1038° against 0.0755°);
each margin here is a separate ``optimise`` run, every pair is compared on the objective both
minimise, and every design is judged again on the workspace grid with its printed walls.
"""

import itertools

import pytest

from reflector_opt.model._surface import get_material
from reflector_opt.optimiser import Problem, optimise
from reflector_opt.optimiser._verify import STRICTER_MARGIN_MM, stricter_levels

#: Required distance margins, mm: above, at and below the default 0.1 mm, and none.
MARGINS_MM = (0.15, 0.1, 0.05, 0.0)

#: Relative difference of two objectives taken as the same design: the polish converges to
#: its tolerance and the last check's repair may move the point it hands over, so the same
#: held level reached from two starts differs in the 7th digit (1.2e-6 seen); distinct
#: designs differ by 1e-3 or more.
SAME = 1e-5


@pytest.fixture(scope="module", params=["white-sla-resin", "polished"])
def runs(request):
    surface = get_material(request.param)
    out = {}
    for margin in MARGINS_MM:
        problem = Problem(surface=surface, distance_margin_mm=margin)
        out[margin] = (problem, optimise(problem, seed=0))
    return out


@pytest.mark.slow
def test_every_design_passes_on_the_workspace_grid_and_its_printed_walls(runs):
    for margin, (problem, result) in runs.items():
        again = problem.check_printed(problem.evaluate(result.evaluation.values))
        assert again.feasible, (margin, again.describe_failure())
        assert again.objective == pytest.approx(result.objective, rel=1e-9)


@pytest.mark.slow
def test_a_relaxed_margin_is_never_worse_than_a_stricter_one(runs):
    for stricter, relaxed in itertools.combinations(MARGINS_MM, 2):
        mine, theirs = runs[relaxed][1].objective, runs[stricter][1].objective
        assert mine <= theirs * (1 + SAME), (
            f"{relaxed} mm: {mine:.5f}° > {stricter} mm: {theirs:.5f}°"
        )
        # the stricter design also meets the relaxed margin: the comparison is fair
        problem = runs[relaxed][0]
        assert problem.check_printed(problem.evaluate(runs[stricter][1].evaluation.values)).feasible


def test_a_smaller_margin_holds_every_level_a_larger_one_holds():
    margins = [0.0, 0.01, 0.02, 0.025, 0.05, 0.06, 0.075, 0.09, 0.1, 0.15]
    for small, large in itertools.combinations(margins, 2):
        assert set(stricter_levels(large)) <= set(stricter_levels(small))
    assert stricter_levels(0.0) == [0.025, 0.05, 0.075, 0.1]
    assert stricter_levels(0.05) == [0.075, 0.1]  # above the margin itself
    assert stricter_levels(STRICTER_MARGIN_MM) == [] and stricter_levels(0.15) == []
