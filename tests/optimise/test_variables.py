"""The optimiser's design variables: the geometry they build, their bounds, the mirror image."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.model._geometry import sensor_distance
from reflector_opt.optimiser import (
    VARIABLES,
    Problem,
)
from reflector_opt.optimiser._variables import z_mirror
from tests.optimise.points import POINT


def test_variables_build_the_declared_geometry():
    problem = Problem()
    design = problem.design(POINT)
    s1, s2 = design.sensors
    assert_allclose(
        s1.position_mm, (10 * np.cos(np.radians(-40)), 10 * np.sin(np.radians(-40)), -0.3)
    )
    assert_allclose(
        s2.position_mm, (10 * np.cos(np.radians(40)), 10 * np.sin(np.radians(40)), -0.3)
    )
    tilt = np.radians(15.0)
    assert_allclose(
        s2.axis,
        (
            -np.cos(np.radians(40)) * np.cos(tilt),
            -np.sin(np.radians(40)) * np.cos(tilt),
            np.sin(tilt),
        ),
    )
    assert design.reflector.centre_mm == pytest.approx((0.9, 0.0, -0.6))
    assert design.reflector.inner_radius_mm == pytest.approx(14.0 / 2 + 0.5)
    # the radius is such that the Eq-3 distance at zero pose is the gap, for both sensors
    d0 = sensor_distance(
        design.positions_mm, design.reflector.centre_mm, design.reflector.radius_mm, 0.0, 0.0
    )
    assert_allclose(d0, 0.8)


def test_the_pair_frame_turns_with_the_pair():
    turned = Problem().design({**POINT, "sensor_azimuth_deg": 90.0, "centre_across_mm": 0.2})
    assert turned.reflector.centre_mm == pytest.approx((-0.2, 0.9, -0.6))
    assert_allclose(
        turned.sensors[0].position_mm[:2],
        (10 * np.cos(np.radians(50)), 10 * np.sin(np.radians(50))),
    )


def test_default_bounds_follow_the_part_and_the_envelope():
    bounds = Problem().bounds
    assert bounds["gap_mm"] == (0.5, 3.0)
    assert bounds["sensor_radius_mm"] == pytest.approx((7.5 + 0.8 + 0.5, 10.0))
    assert bounds["sensor_azimuth_deg"] == (0.0, 0.0)
    assert [v.name for v in VARIABLES] == list(bounds)


def test_z_mirror_keeps_the_tilt():
    m = z_mirror(POINT)
    assert m["centre_z_mm"] == 0.6 and m["sensor_height_mm"] == 0.3
    assert m["sensor_tilt_deg"] == POINT["sensor_tilt_deg"]
