"""Polar boxes about O: containment, horizontal extent and distance from vertical lines."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.design._polar import PolarBox


def test_polar_box_geometry():
    box = PolarBox(7.0, 9.0, -30.0, 30.0, -20.0, 20.0)
    assert box.contains([[8.0, 0.0, 0.0]])[0]
    assert not box.contains([[8.0, 0.0, 6.0]])[0]  # 36.9° elevation
    assert not box.contains([[0.0, 8.0, 0.0]])[0]
    assert box.horizontal_extent() == pytest.approx((7.0 * math.cos(math.radians(30)), 9.0))
    assert box.distance_xy((10.0, 0.0)) == pytest.approx(1.0)
    # Beside the sector, from (0, 9): the nearest point is the corner of the +20° edge at the
    # smallest horizontal radius 7 cos 30° = 6.0622, i.e. (5.6966, 2.0734): 8.968 mm away.
    corner = (
        7.0
        * math.cos(math.radians(30))
        * np.array([np.cos(np.radians(20)), np.sin(np.radians(20))])
    )
    assert box.distance_xy((0.0, 9.0)) == pytest.approx(np.hypot(*(corner - [0.0, 9.0])))
    assert box.contains_box(PolarBox(7.5, 8.5, -10.0, 10.0, -5.0, 5.0))
    assert not box.contains_box(PolarBox(7.5, 9.5, -10.0, 10.0, -5.0, 5.0))


@pytest.mark.parametrize(
    "box", [PolarBox(7.2, 9.5, -20.0, 90.0, 60.0, 120.0), PolarBox(7.0, 9.0, 5.0, 30.0)]
)
def test_polar_box_distance_matches_a_dense_sampling_of_its_footprint(box):
    """Many points at once against the nearest of 450,000 points filling the projected sector."""
    points = np.random.default_rng(0).uniform(-12.0, 12.0, (100, 2))
    rho_lo, rho_hi = box.horizontal_extent()
    a0, a1 = (box.a0, box.a1) if box.a0 is not None else (0.0, 360.0)
    radii, azimuths = np.linspace(rho_lo, rho_hi, 300), np.radians(np.linspace(a0, a1, 1500))
    rho, azimuth = np.meshgrid(radii, azimuths)
    footprint = np.column_stack([(rho * np.cos(azimuth)).ravel(), (rho * np.sin(azimuth)).ravel()])
    nearest = [np.hypot(*(footprint - p).T).min() for p in points]
    spacing = max(radii[1] - radii[0], rho_hi * (azimuths[1] - azimuths[0]))  # its resolution
    assert_allclose(box.distance_xy(points), nearest, atol=spacing)
