"""Fitting strategies: the coefficients of a linear model X k ≈ y, one output column at a time.

- ``"lsq"`` ordinary least squares (LAPACK via :func:`numpy.linalg.lstsq`);
- ``"huber"`` the Huber loss (quadratic within a threshold, linear beyond; robust to outliers);
- ``"minimax"`` the smallest maximum absolute error (a linear programme).

The last two are solved with cvxpy, starting from the least-squares solution; a solver that does
not report an optimal solution raises :class:`~reflector_opt.util._errors.FitError`. The minimax
programme is solved by constraint exchange: the LP on a working set of samples gives a lower
bound on the optimum, the worst samples of the full set are added until every sample lies within
the bound (to 1e-6°), which certifies the result optimal for the full set. The Huber problem is
solved by a similar exchange over which samples lie inside the threshold
(:func:`huber_column`).
"""

import math
import numbers
from typing import NamedTuple

import numpy as np

from reflector_opt.calibration._choices import FITS
from reflector_opt.util._errors import FitError, InputError

# Singular values below this fraction of the largest count as zero: the voltages do not
# determine the coefficients.
RANK_RTOL = 1e-10
# Default Huber threshold = this constant times a robust residual scale (95 % efficiency under
# Gaussian noise, Huber 1981); never below the floor, in degrees.
_HUBER_K = 1.345
_HUBER_FLOOR_DEG = 1e-3
# Exchange algorithms (Huber, minimax) stop when every sample is within this tolerance of its
# assumed region (Huber: threshold units; minimax: degrees, relative to 1 + bound).
_EXCHANGE_TOL = 1e-6
_EXCHANGE_ROUNDS = 100
# The Huber exchange starts with the samples whose starting residual lies within this band
# around the threshold (relative) as explicit Huber terms.
_HUBER_BAND = 0.1
DEFAULT_SOLVERS = {"huber": ("OSQP", "CLARABEL"), "minimax": ("HIGHS", "CLARABEL")}


class Fit(NamedTuple):
    """The result of :func:`fit_coefficients`."""

    #: Coefficients, shape (n_terms, n_outputs).
    coef: np.ndarray
    #: Huber threshold of each output column (``"huber"`` only, else None).
    threshold: np.ndarray | None
    #: Name of the cvxpy solver of the last column (None for least squares).
    solver: str | None


def check_method(method, threshold=None):
    """Raise :class:`InputError` unless ``method`` is one of :data:`FITS` and ``threshold``
    (the Huber threshold, degrees) is None or positive."""
    if method not in FITS:
        raise InputError(f"unknown fit {method!r}; choose one of {', '.join(FITS)}")
    if threshold is not None and (
        isinstance(threshold, bool)
        or not isinstance(threshold, numbers.Real)
        or not 0 < threshold < math.inf
    ):
        raise InputError(f"huber_threshold_deg: must be a positive number, got {threshold!r}")


def fit_coefficients(X, Y, method, what, threshold=None, solver=None, labels=None):
    """Fit ``X k ≈ Y`` column by column with one of :data:`FITS`.

    Parameters
    ----------
    X : numpy.ndarray
        Design matrix, shape (n_samples, n_terms).
    Y : numpy.ndarray
        Targets, shape (n_samples, n_outputs).
    method : {"lsq", "huber", "minimax"}
    what : str
        Prefix of error messages.
    threshold : float, optional
        Huber threshold in the units of ``Y``; default 1.345 × the least-squares residuals'
        robust scale per column (at least 1e-3).
    solver : str, optional
        cvxpy solver name; default OSQP then Clarabel (Huber), HiGHS then Clarabel (minimax).
    labels : sequence of str, optional
        Names of the output columns, for error messages.

    Returns
    -------
    Fit

    Raises
    ------
    InputError
        Unknown ``method`` or a threshold that is not positive.
    FitError
        ``X`` is rank-deficient, or the solver failed.
    """
    check_method(method, threshold)
    coef = lstsq(X, Y, what)
    if method == "lsq":
        return Fit(coef, None, None)
    thresholds = None
    if method == "huber":
        if threshold is None:
            thresholds = np.maximum(_HUBER_K * robust_scale(X @ coef - Y), _HUBER_FLOOR_DEG)
        else:
            thresholds = np.full(Y.shape[1], float(threshold))
    solvers = (solver,) if solver else DEFAULT_SOLVERS[method]
    columns = []
    for j in range(Y.shape[1]):
        where = f"{what} ({labels[j]})" if labels else what
        if method == "huber":
            columns.append(huber_column(X, Y[:, j], thresholds[j], coef[:, j], solvers, where))
        else:
            columns.append(minimax_column(X, Y[:, j], coef[:, j], solvers, where))
    return Fit(np.stack([c for c, _ in columns], axis=1), thresholds, columns[-1][1])


def lstsq(X, Y, what):
    """Least-squares coefficients; a rank-deficient ``X`` raises :class:`FitError`."""
    coef, _, _, singular = np.linalg.lstsq(X, Y, rcond=None)
    rank = int(np.sum(singular > RANK_RTOL * singular[0])) if singular.size else 0
    if rank < X.shape[1]:
        raise FitError(
            f"{what}: the voltages do not determine the {X.shape[1]} coefficients "
            f"(design matrix rank {rank}); the samples must span the workspace"
        )
    return coef


def solve(problem, solvers, what):
    """Solve a cvxpy problem with the first solver that reports it optimal; return its name."""
    import cvxpy as cp

    outcomes = []
    for solver in solvers:
        try:
            problem.solve(solver=solver)
        except (cp.error.SolverError, ValueError) as exc:
            outcomes.append(f"{solver}: {str(exc).splitlines()[0] if str(exc) else 'failed'}")
            continue
        if problem.status == cp.OPTIMAL:
            return solver
        outcomes.append(f"{solver}: {problem.status}")
    raise FitError(f"{what}: no optimal solution ({'; '.join(outcomes)})")


def robust_scale(residual):
    """Normalised median absolute deviation of each column (σ for Gaussian residuals)."""
    centred = residual - np.median(residual, axis=0)
    return 1.4826 * np.median(np.abs(centred), axis=0)


def huber_column(X, y, threshold, start, solvers, what):
    """Minimise Σ huber((X k − y) / threshold) exactly, with a small cvxpy problem per round.

    Samples whose residual is clearly inside the threshold enter through their least-squares
    normal equations (an n×n triangular factor), samples clearly outside through a linear
    term, and only the uncertain rest as explicit Huber terms. At the solution every sample's
    assumed region is checked; wrong ones become explicit and the problem is solved again.
    When all hold, the gradient of the full Huber objective vanishes: the result is optimal.

    Returns
    -------
    tuple
        The coefficients and the name of the solver used.
    """
    import cvxpy as cp

    n = X.shape[1]
    Xs, ys = X / threshold, y / threshold
    residual = Xs @ start - ys
    sign = np.sign(residual)
    quadratic = np.abs(residual) <= 1.0 - _HUBER_BAND
    linear = np.abs(residual) >= 1.0 + _HUBER_BAND
    for _ in range(_EXCHANGE_ROUNDS):
        q_factor, r_factor = np.linalg.qr(Xs[quadratic])
        if np.linalg.matrix_rank(r_factor) < n:
            quadratic[:] = linear[:] = False
        explicit = ~(quadratic | linear)
        k = cp.Variable(n)
        objective = 2.0 * (sign[linear] @ Xs[linear]) @ k
        if quadratic.any():
            objective += cp.sum_squares(r_factor @ k - q_factor.T @ ys[quadratic])
        if explicit.any():
            objective += cp.sum(cp.huber(Xs[explicit] @ k - ys[explicit], 1.0))
        used = solve(cp.Problem(cp.Minimize(objective)), solvers, what)
        residual = Xs @ k.value - ys
        wrong = (quadratic & (np.abs(residual) > 1.0 + _EXCHANGE_TOL)) | (
            linear & (sign * residual < 1.0 - _EXCHANGE_TOL)
        )
        if not wrong.any():
            return k.value, used
        quadratic &= ~wrong
        linear &= ~wrong
    raise FitError(f"{what}: the exchange did not converge in {_EXCHANGE_ROUNDS} rounds")


def minimax_column(X, y, start, solvers, what):
    """Minimise ``max |X k − y|`` by constraint exchange; the result is certified on all rows.

    Returns
    -------
    tuple
        The coefficients and the name of the solver used.
    """
    import cvxpy as cp

    m, n = X.shape
    residual = np.abs(X @ start - y)
    spread = np.linspace(0, m - 1, min(m, 50 * n)).astype(int)
    work = np.union1d(spread, np.argsort(residual)[-2 * n :])
    for _ in range(_EXCHANGE_ROUNDS):
        k, t = cp.Variable(n), cp.Variable()
        r = X[work] @ k - y[work]
        used = solve(cp.Problem(cp.Minimize(t), [r <= t, -r <= t]), solvers, what)
        residual = np.abs(X @ k.value - y)
        limit = float(t.value) + _EXCHANGE_TOL * (1.0 + abs(float(t.value)))
        violators = np.flatnonzero(residual > limit)
        if violators.size == 0:
            return k.value, used
        worst = violators[np.argsort(residual[violators])[-5 * n :]]
        work = np.union1d(work, worst)
    raise FitError(f"{what}: the exchange did not converge in {_EXCHANGE_ROUNDS} rounds")
