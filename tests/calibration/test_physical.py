"""Physical calibration: parameter recovery, inversion and its covariance, file and CLI."""

from dataclasses import replace

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.analysis._jacobian import voltage_jacobian
from reflector_opt.analysis._resolution import crlb_deg
from reflector_opt.calibration._coefficients import model_from_dict, model_to_dict
from reflector_opt.calibration._files import write_calibration_csv, write_voltage_log
from reflector_opt.calibration._physical import PARAMETERS, PhysicalModel, fit_residual
from reflector_opt.calibration._plans import make_plan
from reflector_opt.calibration._simulation import measure_with_design_noise
from reflector_opt.cli import main
from reflector_opt.util._errors import InputError

#: Known perturbations of every parameter (gains, offsets V, centre mm, tilts °, f).
SHIFT = np.array([0.03, -0.02, 0.01, -0.015, 0.04, -0.03, 0.05, 0.8, -0.6, -0.5, 0.9, 0.05])


def _unit(design):
    """A perturbed unit's true parameters, a 100-pose plan and its noise-free voltages."""
    nominal = PhysicalModel(design)
    x = nominal.nominal + SHIFT
    plan = make_plan(design.workspace, "grid", 100)
    return nominal, x, plan, nominal._volts(x, plan[:, 0], plan[:, 1])


def test_recovers_known_perturbations_from_quiet_data(design):
    quiet = design.replace(noise=replace(design.noise, sigma_v=1e-5, adc_bits=24))
    _, x, plan, volts = _unit(quiet)
    fitted = PhysicalModel(quiet).fit(volts, plan)
    assert_allclose(fitted.x_, x, atol=1e-4)
    assert [name for name, _ in PARAMETERS] == list(fitted.params_)


@pytest.fixture(scope="module")
def noisy(design):
    """The perturbed unit calibrated on noisy data, and fresh validation data from it."""
    nominal, x, plan, volts = _unit(design)
    rng = np.random.default_rng(1)
    fitted = PhysicalModel(design).fit(measure_with_design_noise(design, volts, rng), plan)
    poses = rng.uniform(-15, 15, (3000, 2))
    clean = nominal._volts(x, poses[:, 0], poses[:, 1])
    return {
        "x": x,
        "nominal": nominal,
        "fitted": fitted,
        "poses": poses,
        "volts": measure_with_design_noise(design, clean, rng),
    }


def test_noisy_fit_is_close_and_its_estimates_reach_the_bound(design, noisy):
    fitted, x, poses = noisy["fitted"], noisy["x"], noisy["poses"]
    # with noise the parameters trade against each other (gain, tilt and f all scale the
    # signal), but the fitted voltage map is the unit's to well under the noise
    truth = noisy["nominal"]._volts(x, poses[:, 0], poses[:, 1])
    mapped = fitted._volts(fitted.x_, poses[:, 0], poses[:, 1])
    assert np.sqrt(np.mean((mapped - truth) ** 2)) < 0.3 * design.noise.total_sigma_v
    estimate, cov = fitted.predict(noisy["volts"], return_cov=True)
    error = estimate - noisy["poses"]
    rms = np.sqrt(np.mean(error**2, axis=0))
    # independent bound: the true unit's Cramér–Rao bound from its own Jacobian
    unit = noisy["nominal"].unit_design(x)
    gain = x[:2][:, None]
    jac = voltage_jacobian(unit, noisy["poses"][:, 0], noisy["poses"][:, 1]) * gain
    floor = np.sqrt([np.mean(s**2) for s in crlb_deg(jac, design.noise.total_sigma_v)])
    assert np.all(rms < 1.15 * floor)
    # the stated covariance describes the actual errors
    z2 = np.mean(error**2 / np.stack([cov[:, 0, 0], cov[:, 1, 1]], -1), axis=0)
    assert_allclose(z2, 1.0, atol=0.15)


def test_file_round_trip_predicts_the_same(noisy):
    fitted = noisy["fitted"]
    again = model_from_dict(model_to_dict(fitted))
    assert_allclose(again.predict(noisy["volts"][:50]), fitted.predict(noisy["volts"][:50]))
    data = model_to_dict(fitted)
    data["parameters"].pop("gain_1")
    with pytest.raises(InputError, match="parameters"):
        model_from_dict(data)


def test_too_few_samples_and_unfitted_are_refused(design):
    with pytest.raises(InputError, match="too few"):
        PhysicalModel(design).fit(np.ones((5, 2)), np.zeros((5, 2)))
    with pytest.raises(InputError, match="not fitted"):
        PhysicalModel(design).predict(np.ones((1, 2)))


def test_cli_calibrates_physical_and_estimate_reads_it(design, noisy, tmp_path, capsys):
    plan = make_plan(design.workspace, "sobol", 50, seed=2)
    clean = noisy["nominal"]._volts(noisy["x"], plan[:, 0], plan[:, 1])
    volts = measure_with_design_noise(design, clean, np.random.default_rng(4))
    write_calibration_csv(tmp_path / "data.csv", ["1"] * 50, volts, plan)
    design.save(tmp_path / "design.json")
    write_voltage_log(tmp_path / "log.csv", range(20), ["1"] * 20, noisy["volts"][:20])
    coef = tmp_path / "coef.json"
    args = ["calibrate", tmp_path / "data.csv", "--model", "physical", "--folds", "0"]
    assert main([str(a) for a in [*args, "--design", tmp_path / "design.json", "-o", coef]]) == 0
    assert "calibrated with physical" in capsys.readouterr().out
    out = tmp_path / "angles.csv"
    assert main(["estimate", str(coef), str(tmp_path / "log.csv"), "-o", str(out)]) == 0
    table = np.genfromtxt(out, delimiter=",", names=True)
    assert_allclose(table["1_pitch_deg"], noisy["poses"][:20, 0], atol=0.5)
    capsys.readouterr()
    assert main([str(a) for a in [*args, "-o", tmp_path / "x.json"]]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--design" in err[0]
    assert not (tmp_path / "x.json").exists()


def test_the_fits_jacobian_matches_central_differences_of_its_residual(design):
    """Exact gain and offset columns, forward differences for the geometry: the Jacobian the
    fit is given agrees with an independent central-difference one at a perturbed unit."""
    nominal, x, plan, volts = _unit(design)
    bounds = (np.full(len(PARAMETERS), -np.inf), np.full(len(PARAMETERS), np.inf))
    residual, jacobian = fit_residual(nominal, volts + 0.01, plan, bounds)
    given = jacobian(x)
    reference = np.empty_like(given)
    for j in range(len(PARAMETERS)):
        h = 1e-5 * max(1.0, abs(x[j]))
        up, down = x.copy(), x.copy()
        up[j] += h
        down[j] -= h
        reference[:, j] = (residual(up) - residual(down)) / (2 * h)
    scale = np.abs(reference).max(axis=0)
    assert np.all(np.abs(given - reference).max(axis=0) <= 1e-3 * scale + 1e-9)
    assert_allclose(given[:, :4], reference[:, :4], rtol=1e-6, atol=1e-6 * scale[:4].max())
