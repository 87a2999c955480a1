"""The printed walls as exact constraints: the CAD's walls, their limit and their linear model."""

import dataclasses
import itertools

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.cad import CadParameters
from reflector_opt.design import Workspace
from reflector_opt.design._layout import plan_layout
from reflector_opt.optimiser import Problem
from reflector_opt.optimiser._printed_walls import (
    DESIGNED_WALLS,
    designed_walls_mm,
    linearised_walls,
)
from tests.optimise.points import POINT, THIN_CHANNEL_WALL, bounds_of, cad_walls


def test_check_printed_judges_the_walls_the_cad_judges():
    problem = Problem(workspace=Workspace(step_deg=0.5))
    start = problem.evaluate(THIN_CHANNEL_WALL)
    assert start.feasible and start.printed_walls_mm is None
    checked = problem.check_printed(start)
    assert not checked.feasible
    c = checked.worst_constraint()
    assert (c.name, c.detail) == ("printed_wall_mm", "body: wall behind a sensor channel")
    walls = cad_walls(start.design)
    assert c.value == pytest.approx(walls["wall behind a sensor channel"])
    # the same wall by brute force: the horizontal gap from each sensor's pad to points of the
    # swept spaces (r, elevation, azimuth through each keep-out), nearest sample then polished
    from scipy.optimize import minimize

    layout = plan_layout(start.design)

    def gap(u, box, pad):
        a0, a1 = (box.a0, box.a1) if box.a0 is not None else (-180.0, 180.0)
        r = box.r0 + u[..., 0] * (box.r1 - box.r0)
        e = np.radians(box.e0 + u[..., 1] * (box.e1 - box.e0))
        a = np.radians(a0 + u[..., 2] * (a1 - a0))
        return np.hypot(r * np.cos(e) * np.cos(a) - pad[0], r * np.cos(e) * np.sin(a) - pad[1])

    axes = [np.linspace(0.0, 1.0, n) for n in (21, 21, 91)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    brute = np.inf
    for pad, box in itertools.product([m.pad_mm for m in layout.sensors], layout.keepouts):
        nearest = grid[np.argmin(gap(grid, box, pad))]
        polished = minimize(gap, nearest, args=(box, pad), bounds=[(0.0, 1.0)] * 3)
        brute = min(brute, polished.fun, gap(nearest, box, pad))
    assert c.value == pytest.approx(brute, abs=1e-6)
    assert c.value < start.design.mechanics.min_wall_mm
    assert len(checked.printed_walls_mm) == len(walls)
    assert f"printed_wall_mm (body: wall behind a sensor channel) is {brute:.2f}" in (
        checked.describe_failure()
    )
    assert set(DESIGNED_WALLS) <= set(checked.printed_walls_mm)


def test_a_design_on_the_wall_limit_is_feasible_and_a_hair_past_it_is_not():
    """The exact printed-wall constraint, at a minimum wall equal to the design's thinnest."""
    problem = Problem(workspace=Workspace(step_deg=0.5))
    evaluation = problem.evaluate(POINT)
    thinnest = min(cad_walls(evaluation.design).values())
    for mechanics_wall, feasible in ((thinnest, True), (thinnest + 1e-6, False)):
        mechanics = dataclasses.replace(problem.mechanics, min_wall_mm=mechanics_wall)
        at_limit = Problem(workspace=Workspace(step_deg=0.5), mechanics=mechanics)
        checked = at_limit.check_printed(at_limit.evaluate(POINT))
        c = checked.constraints_dict()["printed_wall_mm"]
        assert c["met"] is feasible, (mechanics_wall, c)


def test_linearised_walls_are_exact_at_the_point_and_predict_a_step():
    problem = Problem(workspace=Workspace(step_deg=0.5))
    names, lower, upper = bounds_of(problem)
    x = np.array([THIN_CHANNEL_WALL[n] for n in names])
    model, layouts = linearised_walls(problem, x, lower, upper)
    assert layouts == 1 + len(names)
    exact = dict(zip(DESIGNED_WALLS, designed_walls_mm(problem, THIN_CHANNEL_WALL), strict=True))
    assert "body: wall behind a sensor channel" in model.names
    assert_allclose(model.margins(model.at) + model.limit, [exact[n] for n in model.names])
    # a small step in the tilt: the model's prediction against the layout computed afresh
    k = names.index("sensor_tilt_deg")
    u = model.at.copy()
    u[k] += 0.01
    moved = {**THIN_CHANNEL_WALL, "sensor_tilt_deg": lower[k] + u[k] * (upper[k] - lower[k])}
    after = dict(zip(DESIGNED_WALLS, designed_walls_mm(problem, moved), strict=True))
    predicted = model.margins(u) + model.limit
    assert_allclose(predicted, [after[n] for n in model.names], atol=2e-3)


def test_linearised_walls_reuse_the_checked_layout_at_the_point():
    """The walls check_printed laid out at x give the same model, with one layout fewer."""
    problem = Problem(workspace=Workspace(step_deg=0.5))
    names, lower, upper = bounds_of(problem)
    x = np.array([THIN_CHANNEL_WALL[n] for n in names])
    fresh, layouts = linearised_walls(problem, x, lower, upper)
    checked = problem.check_printed(problem.evaluate(THIN_CHANNEL_WALL))
    reused, fewer = linearised_walls(problem, x, lower, upper, None, checked.printed_walls_mm)
    assert fewer == layouts - 1 == len(names)
    assert reused.names == fresh.names
    for field in ("at", "value", "slope", "limit"):
        np.testing.assert_array_equal(getattr(reused, field), getattr(fresh, field))


def test_check_printed_reports_a_design_the_parts_cannot_be_laid_out_for():
    problem = Problem(workspace=Workspace(step_deg=1.0), cad=CadParameters(neck_radius_mm=8.0))
    checked = problem.check_printed(problem.evaluate(POINT))
    assert not checked.feasible
    assert checked.describe_failure().startswith("printed parts: cad.neck_radius_mm")
