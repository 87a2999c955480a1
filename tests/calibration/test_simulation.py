"""Simulated calibration of one unit: protocol, noise propagation, mismatch, drift."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

import reflector_opt as ro
from reflector_opt.calibration._models import Eq5, Eq6, make_model
from reflector_opt.calibration._simulation import (
    Samples,
    assess,
    rig_record,
    run_protocol,
    simulate_calibration,
    simulate_protocol,
    validation_error,
)
from reflector_opt.design import Noise
from reflector_opt.model._noise import Mismatch
from reflector_opt.util._errors import InputError

QUIET = Noise(sigma_v=0.0, adc_bits=32, vref=3.3)  # LSB 0.8 nV: no noise, no quantisation


def design_with(noise):
    return ro.default_design().replace(noise=noise)


def linearised_noise_rms(model, volts, sigma_v):
    """RMS angle noise predicted from the model's voltage gradient: σ·|∇f| per angle."""
    h = 1e-6
    gradient = np.stack(
        [
            (model.predict(volts + h * e) - model.predict(volts - h * e)) / (2 * h)
            for e in np.eye(2)
        ],
        axis=-1,
    )  # (n, angle, sensor)
    return sigma_v * np.sqrt(np.mean(np.sum(gradient**2, axis=-1), axis=0))


def test_protocol_is_the_papers_grid_and_seeded():
    design = ro.default_design()
    protocol = run_protocol(design, n_validation=500, seed=4)
    assert protocol.calibration.angles_deg.shape == (301 * 301, 2)  # ±15° in 0.1° steps
    assert_allclose(np.unique(protocol.calibration.angles_deg[:, 0])[:3], [-15.0, -14.9, -14.8])
    assert protocol.validation.angles_deg.shape == (500, 2)
    assert np.all(np.abs(protocol.validation.angles_deg) <= 15.0)
    again = run_protocol(design, n_validation=500, seed=4)
    assert_allclose(again.validation.volts, protocol.validation.volts)
    assert not np.allclose(
        run_protocol(design, n_validation=500, seed=5).validation.volts, protocol.validation.volts
    )


def test_noise_free_protocol_has_only_model_misfit():
    result = simulate_calibration(design_with(QUIET), "eq6", step_deg=0.5, n_validation=2000)
    assert np.all(result.noise.rms_deg < 1e-6)
    assert_allclose(result.total.rms_deg, result.misfit.rms_deg, atol=1e-6)
    assert np.all(result.misfit.rms_deg > 0.3)  # Eq 6 cannot represent this response exactly
    assert_allclose(result.total.percent, 100 * result.total.rms_deg / 30.0)


@pytest.mark.parametrize(
    ("noise", "sigma_v"),
    [
        (Noise(sigma_v=0.004, adc_bits=32, vref=3.3), 0.004),  # white noise
        (Noise(sigma_v=0.0, adc_bits=8, vref=3.3), 3.3 / 256 / np.sqrt(12)),  # LSB/√12
    ],
)
def test_noise_part_matches_linear_propagation(noise, sigma_v):
    result = simulate_calibration(design_with(noise), "eq6", step_deg=0.5, n_validation=4000)
    expected = linearised_noise_rms(result.model, result.protocol.validation.volts_true, sigma_v)
    assert_allclose(result.noise.rms_deg, expected, rtol=0.06)


def test_static_mismatch_is_absorbed_by_eq6_but_not_by_eq5():
    """Eq 6 and full polynomials are closed under v -> g·v + o per sensor; Eq 5 is not."""
    design = design_with(QUIET)
    mismatch = Mismatch(gain=(1.05, 0.97), offset_v=(0.03, -0.02))
    options = {"step_deg": 1.0, "n_validation": 1000}
    for model, absorbed in ((Eq6(), True), (Eq5(), False)):
        nominal = simulate_calibration(design, model, **options).total.rms_deg
        built = simulate_calibration(design, model, mismatch=mismatch, **options).total.rms_deg
        assert np.allclose(nominal, built, rtol=1e-7) == absorbed


def test_drift_after_calibration_shifts_the_estimate():
    design = design_with(QUIET)
    delta = 0.01  # V on sensor 1 after calibration
    options = {"step_deg": 0.5, "n_validation": 2000, "seed": 1}
    base = simulate_calibration(design, "eq6", **options)
    drifted = simulate_calibration(
        design, "eq6", drift=Mismatch(gain=(1.0, 1.0), offset_v=(delta, 0.0)), **options
    )
    # First order: the estimate moves by δ·∂f/∂v1 at every validation pose.
    volts = base.protocol.validation.volts_true
    step = np.array([1e-6, 0.0])
    slope = (base.model.predict(volts + step) - base.model.predict(volts - step)) / (2 * step[0])
    expected = np.sqrt(np.mean((delta * slope) ** 2, axis=0))
    assert_allclose(drifted.noise.rms_deg, expected, rtol=0.03)
    assert drifted.noise.rms_deg[0] > 0.2  # sensor 1 mostly senses pitch
    assert_allclose(drifted.misfit.rms_deg, base.misfit.rms_deg)


def test_result_summary_keys_and_model_instances():
    result = simulate_calibration(
        ro.default_design(), Eq5(intercept=True), step_deg=1.0, n_validation=500
    )
    summary = result.to_dict()
    assert summary["model"] == "eq5" and summary["params"]["intercept"] is True
    for key in ("rms_deg", "max_deg", "percent_error", "misfit_rms_deg", "noise_rms_deg"):
        assert set(summary[key]) == {"pitch", "roll"}
    assert summary["n_calibration"] == 31 * 31
    assert_allclose(
        result.estimate(result.protocol.validation.volts)[0],
        result.model.predict(result.protocol.validation.volts[0]),
    )


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"n_validation": 0}, "n_validation"),
        ({"step_deg": -0.1}, "step_deg"),
        ({"n_validation": 10**12}, "n_validation: must be a whole number from 1 to 1,000,000"),
        ({"n_validation": 2.5}, "n_validation"),
        ({"step_deg": 1e-7}, "step_deg = 1e-07°: asks for"),
    ],
)
def test_bad_protocol_options(options, message):
    with pytest.raises(InputError, match=message):
        run_protocol(ro.default_design(), **options)


class _LinearUnit:
    """A unit whose voltages are V = 0.1 + A·(pitch, roll) exactly (V/deg), with noise σ."""

    A = np.array([[0.02, 0.005], [-0.004, 0.03]])

    def __init__(self, sigma_v):
        self.sigma_v = sigma_v
        self.phases = []

    def __call__(self, angles_deg, rng, in_use):
        self.phases.append(in_use)
        angles = np.asarray(angles_deg, dtype=float)
        true = 0.1 + angles @ self.A.T
        return Samples(angles, true, true + rng.normal(0.0, self.sigma_v, true.shape))


def test_the_simulated_protocol_records_the_plan_then_uniform_validation_poses():
    workspace = ro.default_design().workspace
    plan = workspace.poses(5.0)
    assert plan.shape == (49, 2)  # 7 × 7, pitch-major
    assert_allclose(plan[:2], [[-15.0, -15.0], [-15.0, -10.0]])
    unit = _LinearUnit(0.001)
    protocol = simulate_protocol(unit, workspace, plan, 300, np.random.default_rng(3), seed=3)
    assert unit.phases == [False, True]  # calibration first, then in use
    # the same generator, drawn by hand in the documented order: noise, poses, noise
    rng = np.random.default_rng(3)
    rng.normal(0.0, 0.001, (49, 2))
    assert_allclose(protocol.validation.angles_deg, rng.uniform([-15, -15], [15, 15], (300, 2)))
    assert_allclose(protocol.span_deg, [30.0, 30.0])
    assert np.isnan(protocol.step_deg) and protocol.seed == 3
    with pytest.raises(InputError, match="n_validation"):
        simulate_protocol(unit, workspace, plan, 0, np.random.default_rng(3))


def test_validation_error_of_a_linear_unit_is_the_least_squares_noise():
    """A linear unit calibrated by a linear model (poly1): the validation error is the noise
    carried through A⁻¹ (its misfit is zero), σ_θ = σ_V·sqrt(diag((AᵀA)⁻¹)) by hand."""
    workspace = ro.default_design().workspace
    unit = _LinearUnit(0.002)
    protocol = simulate_protocol(
        unit, workspace, workspace.poses(1.0), 20000, np.random.default_rng(1)
    )
    _, total = validation_error(make_model("poly1"), protocol)
    expected = 0.002 * np.sqrt(np.diag(np.linalg.inv(_LinearUnit.A.T @ _LinearUnit.A)))
    assert_allclose(total.rms_deg, expected, rtol=0.03)
    result = assess(make_model("poly1"), protocol)
    assert_allclose(result.total.rms_deg, total.rms_deg)
    assert np.all(result.misfit.rms_deg < 1e-9)


def test_a_rig_records_the_voltages_with_noise_then_the_reference_with_its_own():
    """By hand, the same generator: the voltage noise and ADC first, then the angle noise."""
    design = design_with(Noise(sigma_v=0.003, adc_bits=32, vref=3.3))
    poses = np.array([[1.0, -2.0], [10.0, 5.0], [-4.0, 0.5]])  # voltages inside the ADC

    def volts(pitch, roll):
        return 0.1 + np.stack([pitch, roll], axis=-1) @ _LinearUnit.A.T

    samples = rig_record(volts, design, poses, np.random.default_rng(8), 0.05)
    rng = np.random.default_rng(8)
    true = 0.1 + poses @ _LinearUnit.A.T
    assert_allclose(samples.volts_true, true)
    assert_allclose(samples.volts, true + rng.normal(0.0, 0.003, true.shape), atol=1e-9)
    assert_allclose(samples.angles_deg, poses + rng.normal(0.0, 0.05, poses.shape))
