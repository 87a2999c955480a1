"""The polish: a tightened constraint met, steps through the given map, the other basins."""

import numpy as np

from reflector_opt.optimiser import Problem
from reflector_opt.optimiser._polish import other_basins, polish
from tests.optimise.points import POINT, bounds_of


def test_polish_meets_a_tightened_constraint():
    """The repair step: the polish honours extra margin demanded of a constraint."""
    problem = Problem()
    names = problem.free_names
    lower = np.array([problem.search_bounds[n][0] for n in names])
    upper = np.array([problem.search_bounds[n][1] for n in names])
    x0 = np.array([POINT[n] for n in names])
    x, n = polish(problem, x0, lower, upper, 3.0, 60, tightening={"distance_margin_mm": 0.1})
    assert n > len(names)
    e = problem.evaluate(dict(zip(names, x, strict=True)) | problem.fixed_values, 3.0)
    assert e.feasible
    margin = next(c for c in e.constraints if c.name == "distance_margin_mm")
    assert margin.value >= 0.2 - 1e-6


def test_polish_computes_each_step_with_the_given_map_and_the_same_result():
    """The forward differences go through ``map_`` (a worker pool's in a run), each point
    once; the polish reaches the same point, with the same evaluations, as with ``map``."""
    problem = Problem()
    names = problem.free_names
    lower = np.array([problem.search_bounds[n][0] for n in names])
    upper = np.array([problem.search_bounds[n][1] for n in names])
    x0 = np.array([POINT[n] for n in names])
    batches = []

    def recording_map(function, points):
        batches.append(len(points))
        return [function(p) for p in points]

    plain = polish(problem, x0, lower, upper, 3.0, 5)
    mapped = polish(problem, x0, lower, upper, 3.0, 5, map_=recording_map)
    np.testing.assert_array_equal(mapped[0], plain[0])
    assert mapped[1] == plain[1]
    assert batches and all(b == len(names) for b in batches)  # one batch a Jacobian
    assert sum(batches) < mapped[1]  # the other evaluations: the start and the line search


def test_other_basins_include_the_symmetric_layout_only_when_it_is_searched():
    fixed = Problem()
    names, lower, upper = bounds_of(fixed)
    x = np.array([POINT[n] for n in names])
    (mirror,) = other_basins(fixed, x, lower, upper)
    assert mirror[names.index("centre_z_mm")] == 0.6
    free = Problem(bounds={"sensor_azimuth_deg": (0.0, 90.0)})
    names, lower, upper = bounds_of(free)
    x = np.array([{**POINT, "sensor_azimuth_deg": 30.0}[n] for n in names])
    starts = other_basins(free, x, lower, upper)
    i, z = names.index("sensor_azimuth_deg"), names.index("centre_z_mm")
    assert [(s[i], s[z]) for s in starts] == [(30.0, 0.6), (0.0, -0.6), (0.0, 0.6)]
