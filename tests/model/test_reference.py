"""The independent references of the fast model (model.reference): the direct vector
formulation and the Monte Carlo ray count."""

import numpy as np
import pytest

from reflector_opt.design import default_design
from reflector_opt.model._exact import exact_coupling
from reflector_opt.model._reference import direct_response, raytrace_coupling
from reflector_opt.model._sensors import NJL5901R_2 as NJL
from tests.model.ray_estimators import GEOMETRIES, setting


def test_direct_distance_at_the_zero_pose_by_hand():
    # Default design: sensors 10 mm out on x and y, sphere R = 9 mm centred 1.4 mm below O.
    # Eq 3 at the zero pose: |f − s1| − R = sqrt(10² + 1.4²) − 9 = 1.09752 mm for both.
    design = default_design()
    distance, coupling, volts = direct_response(design, 0.0, 0.0)
    assert distance == pytest.approx([np.sqrt(101.96) - 9.0] * 2, abs=1e-12)
    assert coupling.shape == volts.shape == (2,)
    assert coupling[0] == pytest.approx(coupling[1], rel=1e-12)  # the two sensors' symmetry
    expected = [m.output_voltage(c) for m, c in zip(design.models, coupling, strict=True)]
    assert volts == pytest.approx(expected, rel=1e-12)


def test_the_monte_carlo_ray_count_agrees_within_its_standard_error():
    """``reference.raytrace_coupling`` (the examples' independent check): 4 standard errors."""
    args = (*setting(*GEOMETRIES[2]), NJL)
    exact = exact_coupling(*args)
    counted, error = raytrace_coupling(*args, n_rays=1_000_000, seed=3)
    assert abs(counted.mirror - exact.mirror) < 4 * error.mirror
    assert abs(counted.lambertian - exact.lambertian) < 4 * error.lambertian
