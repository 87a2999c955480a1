"""Calibration models: exact recovery, noisy recovery, the three fits, JSON, bad input."""

import json

import numpy as np
import pytest
import scipy.linalg
from numpy.testing import assert_allclose
from scipy.optimize import least_squares, linprog

import reflector_opt as ro
from reflector_opt.calibration.models import (
    Eq5,
    Eq6,
    Polynomial,
    _solve,
    cross_validate,
    load_model,
    make_model,
    model_from_dict,
)
from reflector_opt.util.errors import FitError, InputError

# Known Eq 6 coefficients, the paper's order: v1, v2, v1², v2², v1·v2, v1·v2², v2·v1², 1.
K_PITCH = np.array([-40.0, -2.0, 13.0, 0.4, 1.4, -0.26, -0.04, 17.0])
J_ROLL = np.array([-6.6, 38.0, 1.7, -14.0, 2.0, 0.2, -0.6, -10.0])


def eq6_by_hand(volts, k):
    """Paper Eq 6 written out term by term (independent of the package's monomials)."""
    v1, v2 = volts[:, 0], volts[:, 1]
    return (
        k[0] * v1
        + k[1] * v2
        + k[2] * v1**2
        + k[3] * v2**2
        + k[4] * v1 * v2
        + k[5] * v1 * v2**2
        + k[6] * v2 * v1**2
        + k[7]
    )


def synthetic(n, seed=0, sigma_deg=0.0):
    """Voltages in the sensors' range and the exact Eq 6 angles (plus optional noise)."""
    rng = np.random.default_rng(seed)
    volts = rng.uniform(1.3, 2.9, size=(n, 2))
    angles = np.column_stack([eq6_by_hand(volts, K_PITCH), eq6_by_hand(volts, J_ROLL)])
    return volts, angles + sigma_deg * rng.standard_normal(angles.shape)


@pytest.fixture(scope="module")
def model_data():
    """The default design's noise-free voltages on a 0.5° grid (the forward model)."""
    design = ro.default_design()
    pitch, roll = np.meshgrid(*design.workspace.axes(0.5), indexing="ij")
    angles = np.column_stack([pitch.ravel(), roll.ravel()])
    return ro.voltages(design, angles[:, 0], angles[:, 1]), angles


# --- exact and noisy recovery ---------------------------------------------------------------------


@pytest.mark.parametrize("fit", ["lsq", "huber", "minimax"])
def test_eq6_recovers_known_coefficients_from_noise_free_data(fit):
    volts, angles = synthetic(400)
    model = Eq6(fit=fit).fit(volts, angles)
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


# --- the three fits ------------------------------------------------------------------------------


def test_minimax_has_the_smallest_maximum_error(model_data):
    volts, angles = model_data
    fits = {f: Eq6(fit=f).fit(volts, angles) for f in ("lsq", "huber", "minimax")}
    worst = {f: m.training_max_deg_ for f, m in fits.items()}
    rms = {f: m.training_rms_deg_ for f, m in fits.items()}
    assert np.all(worst["minimax"] <= worst["lsq"] + 1e-9)
    assert np.all(worst["minimax"] <= worst["huber"] + 1e-9)
    assert np.all(worst["minimax"] < 0.9 * worst["lsq"])  # a real gain on the model's misfit
    assert np.all(rms["lsq"] <= rms["huber"] + 1e-12)
    assert np.all(rms["lsq"] <= rms["minimax"] + 1e-12)


def test_minimax_optimum_matches_scipy_linprog(model_data):
    volts, angles = model_data
    model = Eq6(fit="minimax").fit(volts[::3], angles[::3])
    # The same LP on every sample with HiGHS through scipy: min t, |X k − y| <= t.
    u = (volts[::3] - model.centre_v_) / model.scale_v_
    X = np.stack([u[:, 0] ** a * u[:, 1] ** b for a, b in model.terms], axis=1)
    for j in range(2):
        y = angles[::3, j]
        n = X.shape[1]
        ones = np.ones((len(y), 1))
        result = linprog(
            np.r_[np.zeros(n), 1.0],
            A_ub=np.block([[X, -ones], [-X, -ones]]),
            b_ub=np.r_[y, -y],
            bounds=[(None, None)] * n + [(0, None)],
            method="highs",
        )
        assert result.status == 0
        assert_allclose(model.training_max_deg_[j], result.fun, rtol=1e-6)


def test_huber_matches_scipy_robust_least_squares():
    volts, angles = synthetic(2000, seed=5, sigma_deg=0.1)
    angles[::40] += 5.0
    model = Eq6(fit="huber").fit(volts, angles)
    u = (volts - model.centre_v_) / model.scale_v_
    X = np.stack([u[:, 0] ** a * u[:, 1] ** b for a, b in model.terms], axis=1)
    for j in range(2):
        y, threshold = angles[:, j], model.huber_threshold_deg_[j]
        reference = least_squares(
            lambda k, y=y: X @ k - y,
            np.zeros(X.shape[1]),
            jac=lambda k: X,
            loss="huber",
            f_scale=threshold,
            xtol=1e-10,
            ftol=1e-10,
            gtol=1e-10,
        )
        assert_allclose(model.predict(volts)[:, j], X @ reference.x, atol=1e-5)


@pytest.mark.parametrize("threshold", [None, 0.01, 30.0])
def test_huber_exchange_equals_the_direct_formulation(threshold):
    """Whatever the threshold (most samples quadratic, most linear, all quadratic)."""
    import cvxpy as cp

    volts, angles = synthetic(400, seed=12, sigma_deg=0.3)
    angles[::25] -= 8.0
    model = Eq6(fit="huber", huber_threshold_deg=threshold).fit(volts, angles)
    u = (volts - model.centre_v_) / model.scale_v_
    X = np.stack([u[:, 0] ** a * u[:, 1] ** b for a, b in model.terms], axis=1)
    for j in range(2):
        k = cp.Variable(X.shape[1])
        M = model.huber_threshold_deg_[j]
        cp.Problem(cp.Minimize(cp.sum(cp.huber(X @ k - angles[:, j], M)))).solve("CLARABEL")
        assert_allclose(model.predict(volts)[:, j], X @ k.value, atol=1e-4)


def test_huber_resists_outliers_where_lsq_does_not():
    volts, angles = synthetic(3000, seed=7, sigma_deg=0.05)
    rng = np.random.default_rng(8)
    bad = rng.choice(len(angles), 90, replace=False)  # 3 % gross errors, e.g. IMU glitches
    corrupted = angles.copy()
    corrupted[bad] += rng.uniform(5.0, 20.0, size=(90, 2))
    check, truth = synthetic(2000, seed=9)
    error = {
        fit: np.sqrt(np.mean((Eq6(fit=fit).fit(volts, corrupted).predict(check) - truth) ** 2))
        for fit in ("lsq", "huber")
    }
    assert error["huber"] < 0.05  # close to the clean-data accuracy
    assert error["lsq"] > 0.3  # least squares is dragged by the outliers
    assert error["huber"] < 0.1 * error["lsq"]


def test_fits_agree_on_clean_data():
    volts, angles = synthetic(500, seed=3)
    check, _ = synthetic(100, seed=11)
    predictions = [
        Polynomial(3, fit=f).fit(volts, angles).predict(check) for f in ("lsq", "huber", "minimax")
    ]
    for p in predictions[1:]:
        assert_allclose(p, predictions[0], atol=1e-5)


def test_solver_failures_are_errors():
    volts, angles = synthetic(100)
    with pytest.raises(FitError, match="NOSUCH"):
        Eq6(fit="huber", solver="NOSUCH").fit(volts, angles)

    class Inaccurate:
        status = "optimal_inaccurate"

        def solve(self, solver):
            pass

    with pytest.raises(FitError, match="optimal_inaccurate"):
        _solve(Inaccurate(), ("CLARABEL",), "test fit")


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


# --- cross-validation ----------------------------------------------------------------------------


def test_cross_validation_of_exact_and_noisy_data():
    volts, angles = synthetic(600)
    exact = cross_validate(Eq6(), volts, angles, folds=4)
    assert exact["folds"] == 4 and np.all(exact["rms_deg"] < 1e-8)
    noisy_volts, noisy_angles = synthetic(600, sigma_deg=0.2)
    cv = cross_validate(Eq6(), noisy_volts, noisy_angles, folds=5)
    train = Eq6().fit(noisy_volts, noisy_angles).training_rms_deg_
    assert np.all(cv["rms_deg"] > train)  # held-out error exceeds training error
    assert_allclose(cv["rms_deg"], 0.2, rtol=0.1)


def test_cross_validation_names_the_failing_fold():
    volts, angles = synthetic(10)
    with pytest.raises(InputError, match="fold 1 of 3"):
        cross_validate(Eq6(), volts, angles, folds=3)  # 6 training samples < 8 coefficients
    with pytest.raises(InputError, match="folds"):
        cross_validate(Eq6(), volts, angles, folds=1)


# --- JSON ----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "model", [Eq5(), Eq5(intercept=True), Eq6(fit="huber"), Polynomial(4, fit="minimax")]
)
def test_json_round_trip(tmp_path, model):
    volts, angles = synthetic(300, sigma_deg=0.5)
    model.fit(volts, angles)
    path = tmp_path / "model.json"
    model.save(path)
    loaded = load_model(path)
    assert type(loaded) is type(model)
    assert loaded.get_params() == model.get_params()
    assert_allclose(loaded.predict(volts), model.predict(volts), atol=1e-10)
    assert_allclose(loaded.coef_, model.coef_, rtol=1e-14)
    assert_allclose(loaded.training_rms_deg_, model.training_rms_deg_)
    data = json.loads(path.read_text())
    assert data["coefficients"]["pitch_deg"] == model.coef_[0].tolist()
    assert data["terms"] == model.term_names


def test_model_from_dict_rejects_bad_documents():
    model = Eq6().fit(*synthetic(100))
    good = model.to_dict()
    cases = [
        ({k: v for k, v in good.items() if k != "coefficients"}, "coefficients: missing"),
        ({**good, "model": "eq9"}, "unknown model"),
        ({**good, "coefficients": {"pitch_deg": [1.0] * 7, "roll_deg": [1.0] * 8}}, "8 numbers"),
        ({**good, "input_scale_v": [1.0, 0.0]}, "positive"),
        ({**good, "terms": ["v1"] * 8}, "terms"),
        ({**good, "params": {"fit": "lsq", "colour": 1}}, "params"),
    ]
    for document, message in cases:
        with pytest.raises(InputError, match=message):
            model_from_dict(document)


def test_load_model_errors(tmp_path):
    with pytest.raises(InputError, match="cannot read"):
        load_model(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{")
    with pytest.raises(InputError, match="not valid JSON"):
        load_model(bad)
    bad.write_text('{"format": "something-else"}')
    with pytest.raises(InputError, match="not a calibration model"):
        load_model(bad)


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
    assert poly.degree == 3 and poly.fit_method == "huber" and poly.huber_threshold_deg == 0.5
