"""The exact radiometric reference: convergence, and agreement with ray estimators."""

import numpy as np
import pytest

from reflector_opt.model._exact import exact_coupling, exact_design_coupling
from reflector_opt.model._sensors import NJL5901R_2 as NJL
from tests.model.ray_estimators import (
    GEOMETRIES,
    lambertian_next_event,
    mirror_in_slope_box,
    setting,
)


@pytest.mark.parametrize("geometry", GEOMETRIES)
def test_quadrature_has_converged(geometry):
    args = (*setting(*geometry), NJL)
    default = exact_coupling(*args)
    finer = exact_coupling(*args, source_order=9, detector_order=(5, 12), sphere_order=(160, 144))
    assert abs(default.mirror / finer.mirror - 1) < 1e-4
    assert abs(default.lambertian / finer.lambertian - 1) < 1e-4


@pytest.mark.parametrize("geometry", GEOMETRIES)
def test_agrees_with_low_variance_ray_estimators_to_0_2_percent(geometry):
    """Rays traced in tests/model/ray_estimators.py (a fixed Sobol sequence, no code shared with
    the quadrature): measured within 0.04 % for both parts."""
    args = (*setting(*geometry), NJL)
    exact = exact_coupling(*args)
    assert lambertian_next_event(*args) == pytest.approx(exact.lambertian, rel=2e-3)
    mirror, inset = mirror_in_slope_box(*args)
    assert inset > 0.05  # every detected slope inside the sampled box
    assert mirror == pytest.approx(exact.mirror, rel=2e-3)


def test_design_wrapper_shapes_and_sensor_inside_gives_nothing(design):
    result = exact_design_coupling(design, [0.0, 5.0], 0.0, source_order=2, sphere_order=(24, 24))
    assert result.mirror.shape == result.lambertian.shape == (2, 2)
    assert np.all(result.mirror > 0) and np.all(result.lambertian > 0)
    inside = exact_coupling([0, 0, 0], [1, 0, 0], [0, 0, 0.5], [0.5, 0, 0], 2.0, NJL)
    assert inside.mirror == inside.lambertian == 0.0
