"""The three fits: minimax and Huber against scipy and the direct formulation, solver failures."""

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.optimize import least_squares, linprog

import reflector_opt as ro
from reflector_opt.calibration._fitting import fit_coefficients, solve
from reflector_opt.calibration._models import Eq6, Polynomial
from reflector_opt.util._errors import FitError, InputError
from tests.calibration.eq6_data import synthetic


@pytest.fixture(scope="module")
def model_data():
    """The default design's noise-free voltages on a 0.5° grid (the forward model)."""
    design = ro.default_design()
    pitch, roll = np.meshgrid(*design.workspace.axes(0.5), indexing="ij")
    angles = np.column_stack([pitch.ravel(), roll.ravel()])
    return ro.voltages(design, angles[:, 0], angles[:, 1]), angles


def test_minimax_has_the_smallest_maximum_error(model_data):
    volts, angles = model_data
    fits = {f: Eq6(loss=f).fit(volts, angles) for f in ("lsq", "huber", "minimax")}
    worst = {f: m.training_max_deg_ for f, m in fits.items()}
    rms = {f: m.training_rms_deg_ for f, m in fits.items()}
    assert np.all(worst["minimax"] <= worst["lsq"] + 1e-9)
    assert np.all(worst["minimax"] <= worst["huber"] + 1e-9)
    assert np.all(worst["minimax"] < 0.9 * worst["lsq"])  # a real gain on the model's misfit
    assert np.all(rms["lsq"] <= rms["huber"] + 1e-12)
    assert np.all(rms["lsq"] <= rms["minimax"] + 1e-12)


def test_minimax_optimum_matches_scipy_linprog(model_data):
    volts, angles = model_data
    model = Eq6(loss="minimax").fit(volts[::3], angles[::3])
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
    model = Eq6(loss="huber").fit(volts, angles)
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
    model = Eq6(loss="huber", huber_threshold_deg=threshold).fit(volts, angles)
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
        fit: np.sqrt(np.mean((Eq6(loss=fit).fit(volts, corrupted).predict(check) - truth) ** 2))
        for fit in ("lsq", "huber")
    }
    assert error["huber"] < 0.05  # close to the clean-data accuracy
    assert error["lsq"] > 0.3  # least squares is dragged by the outliers
    assert error["huber"] < 0.1 * error["lsq"]


def test_fits_agree_on_clean_data():
    volts, angles = synthetic(500, seed=3)
    check, _ = synthetic(100, seed=11)
    predictions = [
        Polynomial(3, loss=f).fit(volts, angles).predict(check) for f in ("lsq", "huber", "minimax")
    ]
    for p in predictions[1:]:
        assert_allclose(p, predictions[0], atol=1e-5)


def test_solver_failures_are_errors():
    volts, angles = synthetic(100)
    with pytest.raises(FitError, match="NOSUCH"):
        Eq6(loss="huber", solver="NOSUCH").fit(volts, angles)

    class Inaccurate:
        status = "optimal_inaccurate"

        def solve(self, solver):
            pass

    with pytest.raises(FitError, match="optimal_inaccurate"):
        solve(Inaccurate(), ("CLARABEL",), "test fit")


def test_fit_coefficients_on_a_plain_design_matrix():
    rng = np.random.default_rng(3)
    X = np.column_stack([np.ones(200), rng.uniform(-1, 1, (200, 2))])
    Y = X @ np.array([[1.0, -2.0], [0.5, 3.0], [-4.0, 0.25]])
    for method in ("lsq", "huber", "minimax"):
        result = fit_coefficients(X, Y, method, "test fit", labels=("a", "b"))
        assert_allclose(result.coef, [[1.0, -2.0], [0.5, 3.0], [-4.0, 0.25]], atol=1e-6)
        assert (result.threshold is None) == (method != "huber")
        assert (result.solver is None) == (method == "lsq")
    with pytest.raises(InputError, match="unknown fit"):
        fit_coefficients(X, Y, "l1", "test fit")
    with pytest.raises(InputError, match="positive"):
        fit_coefficients(X, Y, "huber", "test fit", threshold=0.0)
    with pytest.raises(FitError, match="rank 2"):
        fit_coefficients(X[:, [0, 1, 1]], Y, "lsq", "test fit")
