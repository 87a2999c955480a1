"""Built-unit truth: exact optics of a drawn unit, interpolated; the recorded noise."""

import numpy as np
import pytest

from reflector_opt.analysis._jacobian import voltage_jacobian
from reflector_opt.analysis._resolution import crlb_deg
from reflector_opt.model._exact import exact_design_coupling
from reflector_opt.model._forward import voltages
from reflector_opt.tolerance._builtunit import (
    EXACT_ORDERS,
    REFERENCE_SIGMA_DEG,
    build_unit,
    built_unit_protocol,
    crlb_floor_deg,
)
from reflector_opt.util._errors import InputError

POSES = np.array([[3.3, -7.1], [-11.7, 12.9], [14.2, 0.4], [-0.6, -13.8]])


@pytest.fixture(scope="module")
def unit(design):
    return build_unit(design, 0, seed=0)


def _exact_volts(unit, poses, **orders):
    parts = exact_design_coupling(unit.design, poses[:, 0], poses[:, 1], **orders)
    reflector = unit.design.reflector
    eta = parts.total(reflector.reflectance, reflector.specular_fraction)
    out = np.stack([m.output_voltage(eta[:, k]) for k, m in enumerate(unit.design.models)], -1)
    return unit.mismatch.apply(out)


def test_interpolant_matches_the_exact_model_off_its_nodes(unit):
    sigma = unit.design.noise.total_sigma_v
    exact = _exact_volts(unit, POSES, **EXACT_ORDERS)
    error = np.abs(unit.volts(POSES[:, 0], POSES[:, 1]) - exact)
    assert error.max() < 0.1 * sigma  # docs/calibration.md: 0.03 σ_V


def test_truth_orders_agree_with_the_default_quadrature(unit):
    sigma = unit.design.noise.total_sigma_v
    fast = _exact_volts(unit, POSES[:2], **EXACT_ORDERS)
    full = _exact_volts(unit, POSES[:2])
    assert np.abs(fast - full).max() < 0.01 * sigma


def test_built_unit_differs_from_the_nominal_forward_model(design, unit):
    sigma = design.noise.total_sigma_v
    nominal = voltages(design, POSES[:, 0], POSES[:, 1])
    assert np.abs(unit.volts(POSES[:, 0], POSES[:, 1]) - nominal).max() > 10 * sigma
    assert unit.design.reflector.centre_mm != design.reflector.centre_mm
    assert unit.mismatch.gain != (1.0, 1.0)


def test_units_differ_and_repeat_with_their_seed(design, unit):
    again = build_unit(design, 0, seed=0)
    other = build_unit(design, 1, seed=0)
    assert np.array_equal(
        again.volts(POSES[:, 0], POSES[:, 1]), unit.volts(POSES[:, 0], POSES[:, 1])
    )
    assert other.design.reflector != unit.design.reflector


def test_protocol_adds_reference_noise_to_calibration_only(unit):
    poses = np.random.default_rng(3).uniform(-15, 15, (4000, 2))
    protocol = built_unit_protocol(unit, poses, n_validation=300, seed=2)
    noise = protocol.calibration.angles_deg - poses
    assert np.std(noise) == pytest.approx(REFERENCE_SIGMA_DEG, rel=0.05)
    val = protocol.validation
    assert np.array_equal(val.volts_true, unit.volts(val.angles_deg[:, 0], val.angles_deg[:, 1]))
    sigma = unit.design.noise.sigma_v
    assert np.std(val.volts - val.volts_true) == pytest.approx(sigma, rel=0.2)
    with pytest.raises(InputError, match="calibration poses"):
        built_unit_protocol(unit, [[0.0, np.nan]])


def test_floor_is_near_the_nominal_designs_bound(design, unit):
    """An independent path: the nominal design's Cramér–Rao bound on the fast model."""
    poses = np.random.default_rng(5).uniform(-15, 15, (400, 2))
    floor = crlb_floor_deg(unit, poses)
    jac = voltage_jacobian(design, poses[:, 0], poses[:, 1])
    nominal = np.sqrt([np.mean(s**2) for s in crlb_deg(jac, design.noise.total_sigma_v)])
    assert floor == pytest.approx(nominal, rel=0.35)
