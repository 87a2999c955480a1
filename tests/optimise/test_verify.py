"""The verification on the workspace grid: repairs by tightening and polishing, and rejections."""

import numpy as np
import pytest

from reflector_opt.cad import CadParameters
from reflector_opt.design import Workspace
from reflector_opt.optimiser import Problem, SearchBudget
from reflector_opt.optimiser._verify import verify
from tests.optimise.points import POINT, THIN_CHANNEL_WALL, bounds_of, cad_walls

#: The default budget (the verification's polish takes its iterations from it).
TEST_BUDGET = SearchBudget()


def test_verification_repairs_a_per_pose_constraint():
    """A design short of the distance margin on the workspace grid is tightened and polished."""
    problem = Problem(workspace=Workspace(step_deg=0.5), distance_margin_mm=0.15)
    names, lower, upper = bounds_of(problem)
    x = np.array([POINT[n] for n in names])
    start = problem.evaluate(POINT)
    assert [c.name for c in start.constraints if not c.met] == ["distance_margin_mm"]
    counts = {"verify": 0, "polish": 0}
    final, tightening = verify(problem, x, lower, upper, TEST_BUDGET, None, counts)
    assert final.feasible
    assert tightening["distance_margin_mm"] > 0
    assert counts["verify"] >= 2 and counts["polish"] > 0


def test_verification_rejects_what_the_polish_cannot_steer():
    problem = Problem(workspace=Workspace(step_deg=0.5))
    names, lower, upper = bounds_of(problem)
    flat = {**POINT, "centre_along_mm": 0.0, "centre_z_mm": 0.0, "sensor_height_mm": 0.0}
    counts = {"verify": 0, "polish": 0}
    final, tightening = verify(
        problem, np.array([flat[n] for n in names]), lower, upper, TEST_BUDGET, None, counts
    )
    assert not final.feasible and final.worst_constraint().name == "fold_fraction"
    assert tightening == {} and counts == {"verify": 1, "polish": 0}


def test_verification_repairs_a_printed_wall():
    problem = Problem(workspace=Workspace(step_deg=0.5))
    names, lower, upper = bounds_of(problem)
    x = np.array([THIN_CHANNEL_WALL[n] for n in names])
    counts = {"verify": 0, "polish": 0}
    final, _ = verify(problem, x, lower, upper, TEST_BUDGET, None, counts)
    assert final.feasible, final.describe_failure()
    assert counts["verify"] >= 2 and counts["polish"] > 0 and counts["layouts"] > 0
    walls = cad_walls(final.design)
    assert min(walls.values()) >= 0.8
    # the repaired design sits on the wall limit, not behind an inflated margin
    assert min(walls.values()) == pytest.approx(0.8, abs=0.01)
    assert final.constraints_dict()["distance_margin_mm"]["margin"] < 0.01


def test_verification_rejects_a_wall_the_design_cannot_thicken():
    """The dome's wall is a CAD parameter: no design repairs it, the wall is named."""
    problem = Problem(workspace=Workspace(step_deg=0.5), cad=CadParameters(lid_thickness_mm=0.6))
    names, lower, upper = bounds_of(problem)
    x = np.array([POINT[n] for n in names])
    problem_ok = Problem(workspace=Workspace(step_deg=0.5))
    assert problem_ok.check_printed(problem_ok.evaluate(POINT)).feasible
    counts = {"verify": 0, "polish": 0}
    final, tightening = verify(problem, x, lower, upper, TEST_BUDGET, None, counts)
    assert not final.feasible
    assert "printed_wall_mm (reflector: dome) is 0.6 mm" in final.describe_failure()
    assert tightening == {} and counts == {"verify": 1, "polish": 0}
