"""Calibration plans: patterns, sizes, bounds and path length."""

import math

import numpy as np
import pytest
from scipy.stats import qmc

from reflector_opt.calibration._plans import PATTERNS, make_plan, path_length_deg
from reflector_opt.util._errors import InputError


@pytest.mark.parametrize("pattern", [p for p in PATTERNS if p != "raster"])
def test_plans_fill_the_workspace_box(design, pattern):
    plan = make_plan(design.workspace, pattern, 196, seed=1)
    assert plan.shape == (196, 2)
    assert plan.min() >= -15.0 and plan.max() <= 15.0
    # every quarter of the box is visited
    for sp in (-1, 1):
        for sr in (-1, 1):
            assert np.any((np.sign(plan[:, 0]) == sp) & (np.sign(plan[:, 1]) == sr))
    assert len(np.unique(plan, axis=0)) == 196


def test_raster_is_the_papers_protocol(design):
    plan = make_plan(design.workspace, "raster")
    assert plan.shape == (301 * 301, 2)
    assert path_length_deg(plan) == pytest.approx(301 * 30.0 + 300 * 0.1)


def test_grid_path_is_a_serpentine(design):
    plan = make_plan(design.workspace, "grid", 4)
    assert plan.tolist() == [[-15, -15], [-15, 15], [15, 15], [15, -15]]
    assert path_length_deg(plan) == pytest.approx(90.0)


def test_sobol_repeats_with_its_seed_and_bad_input_is_refused(design):
    a = make_plan(design.workspace, "sobol", 50, seed=3)
    assert np.array_equal(a, make_plan(design.workspace, "sobol", 50, seed=3))
    with pytest.raises(InputError, match="pattern"):
        make_plan(design.workspace, "zigzag", 50)
    with pytest.raises(InputError, match="n_poses"):
        make_plan(design.workspace, "grid", 2)


def _greedy_tour(points):
    """The nearest-neighbour tour written plainly: from the first point, always the nearest
    unvisited one (the lowest index among equals)."""
    left, order = list(range(1, len(points))), [0]
    while left:
        d = [float(np.sum((points[j] - points[order[-1]]) ** 2)) for j in left]
        order.append(left.pop(int(np.argmin(d))))
    return points[order]


@pytest.mark.parametrize("n, seed", [(5, 0), (100, 1), (777, 2)])
def test_sobol_plan_is_the_greedy_nearest_neighbour_tour(design, n, seed):
    unit = qmc.Sobol(2, scramble=True, seed=seed).random_base2(math.ceil(math.log2(n)))[:n]
    points = -15.0 + 30.0 * unit  # the default workspace, ±15° in pitch and roll
    plan = make_plan(design.workspace, "sobol", n, seed=seed)
    assert np.array_equal(plan, _greedy_tour(points))
