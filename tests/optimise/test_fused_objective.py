"""The fused evaluation against the straightforward path and the analysis functions."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.analysis._jacobian import voltage_jacobian
from reflector_opt.analysis._resolution import (
    condition_number,
    crlb_deg,
    fold_fraction,
    jacobian_determinant,
    local_separation_sigma,
)
from reflector_opt.design import default_design
from reflector_opt.model._surface import get_material
from reflector_opt.optimiser import Problem
from reflector_opt.optimiser._evaluation import PENALTY, PenalisedObjective
from reflector_opt.optimiser._fused_objective import FusedObjective, judge_poses, search_objective

NEAR_OPTIMUM = {
    "gap_mm": 0.8312,
    "centre_along_mm": 0.9427,
    "centre_across_mm": 0.0,
    "centre_z_mm": 0.7989,
    "sensor_radius_mm": 10.0,
    "sensor_height_mm": 0.2768,
    "sensor_tilt_deg": 3.3357,
    "sensor_azimuth_deg": 0.0,
    "sensor_separation_deg": 84.086,
}


def _sample(problem, n, seed):
    names = problem.free_names
    lower = np.array([problem.search_bounds[k][0] for k in names])
    upper = np.array([problem.search_bounds[k][1] for k in names])
    x0 = np.array([NEAR_OPTIMUM[k] for k in names])
    rng = np.random.default_rng(seed)
    near = x0 + 0.02 * (upper - lower) * rng.standard_normal((n, len(names)))
    return np.clip(
        np.vstack([x0, near, lower + (upper - lower) * rng.random((n, len(names)))]), lower, upper
    )


@pytest.mark.parametrize(
    "problem",
    [
        Problem(),
        Problem(surface=get_material("polished")),
        Problem(specular_fraction_range=(0.0, 0.2)),
        Problem(bounds={"sensor_azimuth_deg": (0.0, 30.0), "centre_across_mm": (-1.0, 1.0)}),
    ],
    ids=["white-resin", "polished", "f-interval", "asymmetric"],
)
def test_fused_objective_is_the_straightforward_one(problem):
    """Same feasibility and objective over candidates near the optimum and across the bounds."""
    reference, fused = PenalisedObjective(problem, 3.0), FusedObjective(problem, 3.0)
    xs = _sample(problem, 12, seed=1)
    a = np.array([reference(x) for x in xs])
    b = np.array([fused(x) for x in xs])
    feasible = a < PENALTY
    assert np.array_equal(feasible, b < PENALTY)
    assert 3 <= feasible.sum() < len(xs)  # the comparison covers both kinds
    assert_allclose(b[feasible], a[feasible], rtol=1e-5)
    # the violations of the infeasible ones
    assert_allclose(b[~feasible] - PENALTY, a[~feasible] - PENALTY, rtol=1e-4, atol=1e-6)


def test_fused_constraints_and_metrics_match_one_by_one():
    problem = Problem()
    reference = PenalisedObjective(problem, 3.0).evaluate_values(NEAR_OPTIMUM)
    fused = FusedObjective(problem, 3.0).evaluate_values(NEAR_OPTIMUM)
    assert [c.name for c in fused.constraints] == [c.name for c in reference.constraints]
    for c, r in zip(fused.constraints, reference.constraints, strict=True):
        assert c.value == pytest.approx(r.value, rel=1e-5, abs=1e-9), c.name
    m, r = fused.metrics, reference.metrics
    assert_allclose(m.resolution_pitch_deg, r.resolution_pitch_deg, rtol=1e-5)
    assert_allclose(m.resolution_roll_deg, r.resolution_roll_deg, rtol=1e-5)
    assert_allclose(m.condition, r.condition, rtol=1e-5)
    assert_allclose(m.wall_mm, r.wall_mm, rtol=1e-12)
    assert m.det_sign == r.det_sign and m.fold_fraction == r.fold_fraction


def test_judge_poses_agrees_with_the_analysis_functions():
    """The compiled pass against resolution.py on the default design's voltages and J."""
    design = default_design()
    pitch, roll = (a.ravel() for a in np.meshgrid(*design.workspace.axes(2.5), indexing="ij"))
    jac = voltage_jacobian(design, pitch, roll)
    sigma = design.noise.total_sigma_v
    n = pitch.size
    res_p, res_r, cond = np.empty(n), np.empty(n), np.empty(n)
    sign, folded, local = judge_poses(jac, sigma, 1.0, res_p, res_r, cond)
    p, r = crlb_deg(jac, sigma)
    assert_allclose(res_p, p, rtol=1e-12)
    assert_allclose(res_r, r, rtol=1e-12)
    assert_allclose(cond, condition_number(jac), rtol=1e-12)
    assert (sign, folded) == fold_fraction(jacobian_determinant(jac))
    assert local == pytest.approx(local_separation_sigma(jac, sigma), rel=1e-12)


def test_judge_poses_reports_a_fold_and_no_sensitivity():
    jac = np.array([[[1.0, 0.0], [0.0, 1.0]], [[0.0, 1.0], [1.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]]])
    out = [np.empty(3) for _ in range(3)]
    sign, folded, local = judge_poses(jac, 1.0, 1.0, *out)
    assert sign in (1, -1) and folded == pytest.approx(2 / 3)
    assert np.isinf(out[0][2]) and np.isinf(out[2][2]) and out[0][0] == 1.0
    assert local == 0.0


def test_search_objective_falls_back_where_the_fused_path_does_not_apply():
    problem = Problem()
    assert isinstance(search_objective(problem, 3.0), FusedObjective)
    assert isinstance(search_objective(problem, 0.5), PenalisedObjective)
