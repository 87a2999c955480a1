"""Calibration models: exact and noisy recovery, Eq 5 on the theoretical model, bad input."""

import numpy as np
import pytest
import scipy.linalg
from numpy.testing import assert_allclose

import reflector_opt as ro
from reflector_opt.calibration._models import Eq5, Eq6, Polynomial, make_model
from reflector_opt.util._errors import FitError, InputError
from tests.calibration.eq6_data import J_ROLL, K_PITCH, synthetic

# --- exact and noisy recovery ---------------------------------------------------------------------


@pytest.mark.parametrize("fit", ["lsq", "huber", "minimax"])
def test_eq6_recovers_known_coefficients_from_noise_free_data(fit):
    volts, angles = synthetic(400)
    model = Eq6(loss=fit).fit(volts, angles)
    # lsq is exact to rounding; the cvxpy fits to their solver tolerance.
    rtol = 1e-9 if fit == "lsq" else 1e-6
    scale = np.abs(np.stack([K_PITCH, J_ROLL])).max()
    assert_allclose(model.coef_, np.stack([K_PITCH, J_ROLL]), rtol=0, atol=rtol * scale)
    paper = model.paper_coefficients()
    assert_allclose([paper[f"k{i}"] for i in range(1, 9)], K_PITCH, atol=rtol * scale)
    assert_allclose([paper[f"j{i}"] for i in range(1, 9)], J_ROLL, atol=rtol * scale)


def test_eq6_lsq_matches_scipy_on_the_raw_design_matrix():
    volts, angles = synthetic(300, seed=4, sigma_deg=0.3)
    v1, v2 = volts.T
    raw = np.column_stack([v1, v2, v1**2, v2**2, v1 * v2, v1 * v2**2, v2 * v1**2, np.ones_like(v1)])
    expected, *_ = scipy.linalg.lstsq(raw, angles)
    assert_allclose(Eq6().fit(volts, angles).coef_, expected.T, rtol=1e-7, atol=1e-8)


def test_noisy_fit_is_within_its_standard_errors():
    sigma = 0.05
    volts, angles = synthetic(3000, seed=2, sigma_deg=sigma)
    model = Eq6().fit(volts, angles)
    v1, v2 = volts.T
    raw = np.column_stack([v1, v2, v1**2, v2**2, v1 * v2, v1 * v2**2, v2 * v1**2, np.ones_like(v1)])
    standard_error = sigma * np.sqrt(np.diag(np.linalg.inv(raw.T @ raw)))
    deviation = np.abs(model.coef_ - np.stack([K_PITCH, J_ROLL])) / standard_error
    assert deviation.max() < 5.0  # 16 coefficients, 5σ: fails with probability < 1e-5
    assert_allclose(model.training_rms_deg_, sigma, rtol=0.05)


@pytest.mark.parametrize("degree", [1, 2, 4])
def test_polynomial_recovers_its_own_coefficients(degree):
    model = Polynomial(degree)
    rng = np.random.default_rng(degree)
    coef = rng.normal(0.0, 5.0, size=(2, len(model.terms)))
    volts = rng.uniform(0.5, 3.0, size=(500, 2))
    powers = np.stack([volts[:, 0] ** a * volts[:, 1] ** b for a, b in model.terms], axis=1)
    model.fit(volts, powers @ coef.T)
    assert_allclose(model.coef_, coef, rtol=0, atol=1e-7 * np.abs(coef).max())
    assert model.term_names[0] == "1"
    assert model.term_names[-1] == ("v2" if degree == 1 else f"v2^{degree}")


def test_eq5_is_linear_without_intercept_and_orders_paper_coefficients():
    rng = np.random.default_rng(0)
    volts = rng.uniform(1.0, 3.0, size=(50, 2))
    k = {"k1": 2.0, "k2": -1.0, "k3": 0.5, "k4": 3.0}  # roll = k1 v1 + k2 v2; pitch = k3, k4
    angles = np.column_stack(
        [
            k["k3"] * volts[:, 0] + k["k4"] * volts[:, 1],
            k["k1"] * volts[:, 0] + k["k2"] * volts[:, 1],
        ]
    )
    model = Eq5().fit(volts, angles)
    assert model.term_names == ["v1", "v2"]
    assert_allclose(model.centre_v_, 0.0)
    assert_allclose(list(model.paper_coefficients().values()), list(k.values()), rtol=1e-10)
    assert_allclose(model.predict([0.0, 0.0]), [0.0, 0.0], atol=1e-12)


def test_raw_coefficients_reproduce_predictions():
    volts, angles = synthetic(200, sigma_deg=1.0)
    for model in (Eq5(), Eq5(intercept=True), Eq6(), Polynomial(3)):
        model.fit(volts, angles)
        powers = np.stack([volts[:, 0] ** a * volts[:, 1] ** b for a, b in model.terms], axis=1)
        assert_allclose(powers @ model.coef_.T, model.predict(volts), atol=1e-9)


# --- the paper's Fig. 5: Eq 5 on the theoretical model ------------------------------------------


def test_eq5_on_theoretical_intensities_follows_the_angles():
    """Paper §3, Fig. 5: a linear map of the two theoretical intensities estimates the angles.

    Calibrate on a 1° grid of the ±15° workspace, estimate independent random poses. The
    model's response is monotone but curved, so a linear map leaves a few degrees of error:
    we require the estimate to explain > 90 % of the angle variance (correlation > 0.95,
    RMS < 3° against the 8.7° RMS of the angles themselves). The paper's printed form has no
    intercept; a map through the origin cannot send the (nonzero) zero-pose intensities to
    zero angle, and on this symmetric design it cannot follow the angles at all.
    """
    design = ro.default_design()
    pitch, roll = np.meshgrid(*design.workspace.axes(1.0), indexing="ij")
    train = np.column_stack([pitch.ravel(), roll.ravel()])
    test = np.random.default_rng(0).uniform(-15, 15, size=(2000, 2))

    def intensities(poses):
        return ro.respond(design, poses[:, 0], poses[:, 1]).coupling

    affine = Eq5(intercept=True).fit(intensities(train), train)
    estimate = affine.predict(intensities(test))
    rms = np.sqrt(np.mean((estimate - test) ** 2, axis=0))
    assert np.all(rms < 3.0)
    for j in range(2):
        assert np.corrcoef(estimate[:, j], test[:, j])[0, 1] > 0.95

    literal = Eq5().fit(intensities(train), train)
    literal_rms = np.sqrt(np.mean((literal.predict(intensities(test)) - test) ** 2, axis=0))
    assert np.all(literal_rms > 5.0)


# --- bad input -----------------------------------------------------------------------------------


def test_bad_fit_inputs():
    volts, angles = synthetic(50)
    with pytest.raises(InputError, match="fewer than the 8 coefficients"):
        Eq6().fit(volts[:7], angles[:7])
    with pytest.raises(InputError, match="same pose"):
        Eq6().fit(volts, np.tile([1.0, 2.0], (50, 1)))
    with pytest.raises(InputError, match="not finite"):
        Eq6().fit(np.where(np.arange(50)[:, None] == 3, np.nan, volts), angles)
    with pytest.raises(InputError, match="shape"):
        Eq6().fit(volts[:, :1], angles)
    with pytest.raises(InputError, match="49 angle samples"):
        Eq6().fit(volts, angles[:49])
    with pytest.raises(FitError, match="rank"):
        Eq6().fit(np.column_stack([volts[:, 0], volts[:, 0]]), angles)
    with pytest.raises(InputError, match="not fitted"):
        Eq6().predict(volts)
    with pytest.raises(InputError, match="last axis"):
        Eq6().fit(volts, angles).predict(volts[:, :1])


@pytest.mark.parametrize(
    ("name", "fit", "message"),
    [
        ("eq7", "lsq", "unknown model"),
        ("poly0", "lsq", "degree"),
        ("poly11", "lsq", "degree"),
        ("eq6", "l1", "unknown fit"),
    ],
)
def test_make_model_rejects_unknown_names(name, fit, message):
    with pytest.raises(InputError, match=message):
        make_model(name, fit)


def test_make_model_builds_each_kind():
    assert isinstance(make_model("EQ5"), Eq5)
    assert isinstance(make_model("eq6", "minimax"), Eq6)
    poly = make_model("poly3", "huber", huber_threshold_deg=0.5)
    assert poly.degree == 3 and poly.loss == "huber" and poly.huber_threshold_deg == 0.5
