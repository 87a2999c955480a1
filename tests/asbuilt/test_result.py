"""An identification's result (asbuilt.result): its uncertainties, a unit's parameters and
its Eq 3 distances with their propagated std, on the print loop's batch of four units
(tests/asbuilt/printloop.py, cached: the batch tests identify the same one)."""

import numpy as np
import pytest

from reflector_opt.model._geometry import rotation_x, rotation_y
from tests.asbuilt.printloop import printed


@pytest.fixture(scope="module")
def result():
    return printed("strong")[1]


def test_stds_and_a_units_covariance_are_the_covariances_parts(result):
    np.testing.assert_allclose(result.std, np.sqrt(np.diag(result.covariance)))
    index = result.layout.unit_indices(1)
    np.testing.assert_array_equal(
        result.unit_covariance(1), result.covariance[np.ix_(index, index)]
    )
    assert result.reference_parameters(1) == {}  # identified with an exact reference


def test_a_units_parameters_are_its_block_of_the_estimate(result):
    block = result.layout.unit_slice(2)
    rows = result.unit_parameters(2)
    assert list(rows) == list(result.layout.unit_names)
    radius = rows["reflector_radius_mm"]
    assert radius["design"] == 9.0
    assert radius["estimate"] == pytest.approx(result.as_built(2)[0].reflector.radius_mm)
    centre_z = rows["reflector_centre_z_mm"]
    k = block.start + result.layout.unit_names.index("reflector_centre_z_mm")
    assert centre_z["estimate"] == pytest.approx(result.x[k])
    assert centre_z["std"] == pytest.approx(result.std[k])
    assert centre_z["posterior_prior_ratio"] == pytest.approx(
        centre_z["std"] / centre_z["prior_std"]
    )


def _eq3(design, pitch, roll):
    """Eq 3 by hand: |f − R(γ, α)·c| − r for each sensor, mm."""
    turned = rotation_x(roll) @ rotation_y(pitch) @ np.asarray(design.reflector.centre_mm)
    return np.linalg.norm(design.positions_mm - turned, axis=1) - design.reflector.radius_mm


def test_distances_and_their_std_by_an_independent_propagation(result):
    value, std = result.distance_mm(0, 5.0, -3.0)
    built, _ = result.as_built(0)
    np.testing.assert_allclose(value, _eq3(built, 5.0, -3.0), atol=1e-12)
    # The std: the gradient by central differences of steps a tenth of each prior std, through
    # the unit's covariance.
    index = result.layout.unit_indices(0)
    gradient = np.zeros((2, len(index)))
    for n, i in enumerate(index):
        h = 0.1 * max(result.layout.prior_std()[i], 1e-6)
        step = np.zeros(result.layout.size)
        step[i] = h
        plus = _eq3(result.layout.unit_design(result.x + step, 0)[0], 5.0, -3.0)
        minus = _eq3(result.layout.unit_design(result.x - step, 0)[0], 5.0, -3.0)
        gradient[:, n] = (plus - minus) / (2 * h)
    expected = np.sqrt(np.einsum("si,ij,sj->s", gradient, result.unit_covariance(0), gradient))
    assert np.all(expected > 1e-4)
    np.testing.assert_allclose(std, expected, rtol=0.02)
