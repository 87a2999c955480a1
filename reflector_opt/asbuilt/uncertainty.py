"""What the data say about the as-built parameters: covariance, determined combinations, profiles.

* **Covariance** (Laplace approximation at the MAP estimate): ``Σ = (J_dᵀ J_d / s² + Σ_p⁻¹)⁻¹``
  with J_d the Jacobian of the weighted data residuals and Σ_p the prior's diagonal
  covariance. s² ≥ 1 is the Birge ratio: the data's χ² per effective degree of freedom, when
  it exceeds 1 — a model that does not describe the unit exactly (model-form error) leaves
  residuals larger than the noise, and the interval widens with them instead of claiming
  the noise alone. The effective number of fitted parameters is the trace of the hat
  matrix, ``tr(J_dᵀ J_d Σ / s²)``.
* **Determined combinations**: the eigenvectors of one unit's covariance (its block and the
  shared surface) whitened by the prior. Along each the posterior std is the square root of
  its eigenvalue times the prior's; a direction is *determined* when that ratio is at most
  :data:`DETERMINED_RATIO`. (With the statistical covariance alone these are the right
  singular vectors of the prior-scaled data Jacobian ``J_d Σ_p^{1/2} / s``, ratio
  ``1/√(1 + σ_i²)``.) Each is named in words by its main terms, e.g.
  "sensor 1 standoff − reflector radius" (FIGAROH's and OpenCV's practice: identify only
  what the data determine and say which combinations those are).
* **Profile likelihood**: the interval of one parameter where twice the negative log
  posterior, minimised over all others, rises by less than the χ²₁ quantile. The
  minimisation over the others is Gauss–Newton with the Jacobian frozen at the MAP
  estimate and the residuals evaluated exactly, so the interval follows the nonlinearity
  of the residuals along the profile (Venzon & Moolgavkar 1988 in spirit).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

__all__ = [
    "DETERMINED_RATIO",
    "Combination",
    "Profile",
    "birge_ratio",
    "combinations",
    "posterior_covariance",
    "profile_interval",
]

#: A parameter or combination is determined by the data when its posterior std is at most
#: this fraction of its prior std.
DETERMINED_RATIO = 0.5

#: A term enters a combination's name when its weight is at least this share of the largest.
_NAMED_SHARE = 0.35

#: At most this many terms are named.
_NAMED_TERMS = 4

#: A term is listed among a combination's weights when its weight is at least this.
_LISTED_WEIGHT = 0.05


def posterior_covariance(data_jacobian, prior_std, inflation):
    """Laplace covariance of the MAP estimate; fixed parameters (prior std 0) get 0.

    Parameters
    ----------
    data_jacobian : numpy.ndarray
        Shape (n_data, p): Jacobian of the weighted data residuals.
    prior_std : numpy.ndarray
        Shape (p,): prior standard deviations (0: a fixed parameter).
    inflation : float
        s² ≥ 1, the Birge ratio (:func:`birge_ratio`).

    Returns
    -------
    numpy.ndarray
        Shape (p, p).
    """
    free = prior_std > 0
    J = data_jacobian[:, free]
    information = J.T @ J / inflation + np.diag(1.0 / prior_std[free] ** 2)
    cov = np.zeros((len(prior_std), len(prior_std)))
    cov[np.ix_(free, free)] = np.linalg.inv(information)
    return cov


def birge_ratio(data_residuals, data_jacobian, prior_std):
    """s² = max(1, χ²_data / (n_data − p_eff)), p_eff the trace of the hat matrix.

    Parameters
    ----------
    data_residuals : numpy.ndarray
        Weighted data residuals at the estimate.
    data_jacobian : numpy.ndarray
    prior_std : numpy.ndarray

    Returns
    -------
    float
    """
    free = prior_std > 0
    J = data_jacobian[:, free]
    information = J.T @ J
    posterior = np.linalg.inv(information + np.diag(1.0 / prior_std[free] ** 2))
    p_eff = float(np.trace(information @ posterior))
    dof = max(len(data_residuals) - p_eff, 1.0)
    return max(1.0, float(data_residuals @ data_residuals) / dof)


@dataclass(frozen=True)
class Combination:
    """A combination of parameters the data determine.

    Attributes
    ----------
    name : str
        In words, e.g. ``"sensor 1 standoff − reflector radius"``.
    weights : dict of str to float
        Parameter name → weight in prior-std units (the unit right singular vector; terms
        below 0.05 left out), largest first.
    ratio : float
        Posterior over prior std along it.
    """

    name: str
    weights: dict
    ratio: float

    def to_dict(self):
        """JSON-ready dict."""
        return {"name": self.name, "weights": self.weights, "posterior_prior_ratio": self.ratio}


def combinations(covariance, prior_std, names, words):
    """The parameter combinations the data determine, best determined first.

    The eigenvectors of the prior-whitened covariance ``Σ_p^{-1/2} Σ Σ_p^{-1/2}`` whose
    eigenvalue is at most :data:`DETERMINED_RATIO` squared: along each, the posterior std is
    that fraction of the prior's or less. With the statistical covariance alone these are the
    right singular vectors of the prior-scaled data Jacobian (eigenvalue 1/(1 + σ_i²)).

    Parameters
    ----------
    covariance : numpy.ndarray
        Shape (p, p): the posterior covariance of one unit's parameters (and the shared).
    prior_std : numpy.ndarray
        Shape (p,).
    names : sequence of str
        The p parameter names.
    words : callable
        Name → plain words.

    Returns
    -------
    list of Combination
    """
    free = prior_std > 0
    scale = prior_std[free]
    whitened = covariance[np.ix_(free, free)] / np.outer(scale, scale)
    free_names = [n for n, f in zip(names, free, strict=True) if f]
    values, vectors = np.linalg.eigh(whitened)
    out = []
    for value, vector in zip(values, vectors.T, strict=True):
        ratio = float(np.sqrt(max(value, 0.0)))
        if ratio > DETERMINED_RATIO:
            break
        out.append(_named(vector, ratio, free_names, words))
    return out


def _named(vector, ratio, names, words):
    """A combination named in words by its main terms."""
    vector = vector * np.sign(vector[np.argmax(np.abs(vector))])
    order = np.argsort(-np.abs(vector))
    terms = [i for i in order if abs(vector[i]) >= _NAMED_SHARE * abs(vector[order[0]])]
    name = words(names[terms[0]])
    for i in terms[1:_NAMED_TERMS]:
        name += f" {'+' if vector[i] > 0 else '−'} {words(names[i])}"
    if len(terms) > _NAMED_TERMS:
        name += f" (and {len(terms) - _NAMED_TERMS} smaller terms)"
    weights = {
        names[i]: round(float(vector[i]), 4) for i in order if abs(vector[i]) >= _LISTED_WEIGHT
    }
    return Combination(name, weights, ratio)


@dataclass(frozen=True)
class Profile:
    """A profile-likelihood interval of one parameter.

    Attributes
    ----------
    name : str
    level : float
        Coverage of the interval (0.9: 90 %).
    low, high : float
        The interval, in the parameter's absolute value.
    closed : bool
        False when the profile did not rise enough within the fit's bounds on one side
        (the bound is then the interval's end).
    """

    name: str
    level: float
    low: float
    high: float
    closed: bool

    def widened(self, extra, estimate, lower, upper):
        """The interval with each side widened in quadrature by ``extra``, within bounds.

        Parameters
        ----------
        extra : float
            Added in quadrature to each side's half-width (e.g. 1.645 × a systematic std).
        estimate : float
            The estimate the sides are measured from.
        lower, upper : float
            The parameter's bounds.

        Returns
        -------
        Profile
        """
        low = estimate - np.hypot(estimate - self.low, extra)
        high = estimate + np.hypot(self.high - estimate, extra)
        closed = self.closed and lower < low and high < upper
        return Profile(
            self.name, self.level, float(max(low, lower)), float(min(high, upper)), closed
        )

    def to_dict(self):
        """JSON-ready dict."""
        return {
            "level": self.level,
            "low": self.low,
            "high": self.high,
            "closed": self.closed,
        }


def _constrained_deviance(residuals, x_hat, jacobian, j, value, inflation, n_data, iterations=6):
    """min over the others of the posterior deviance with parameter j fixed at ``value``."""
    x = x_hat.copy()
    x[j] = value
    others = np.ones(len(x), dtype=bool)
    others[j] = False
    others &= np.any(jacobian != 0, axis=0)
    weights = np.ones(jacobian.shape[0])
    weights[:n_data] = 1.0 / np.sqrt(inflation)
    J = jacobian[:, others] * weights[:, None]
    pseudo = np.linalg.pinv(J)
    for _ in range(iterations):
        r = residuals(x) * weights
        x[others] -= pseudo @ r
    r = residuals(x) * weights
    return float(r @ r)


def profile_interval(name, residuals, x_hat, jacobian, j, std, bounds, inflation, n_data, offset):
    """Profile-likelihood interval of parameter ``j`` at 90 %.

    Two points on each side (1.645 and 3.29 posterior std from the estimate); the signed
    root deviance, near linear in the parameter, is interpolated to ±1.645.

    Parameters
    ----------
    name : str
    residuals : callable
        x → all weighted residuals (data first, then prior).
    x_hat : numpy.ndarray
        The MAP estimate.
    jacobian : numpy.ndarray
        Jacobian of all residuals at ``x_hat``.
    j : int
        The parameter's index.
    std : float
        Its posterior standard deviation.
    bounds : (numpy.ndarray, numpy.ndarray)
        The fit's bounds.
    inflation : float
        s² applied to the data residuals.
    n_data : int
        Number of data residuals (the first ones).
    offset : float
        Added to the deviation to give the parameter's absolute value.

    Returns
    -------
    Profile
    """
    level = 0.9
    target = float(np.sqrt(chi2.ppf(level, 1)))
    base = _constrained_deviance(residuals, x_hat, jacobian, j, x_hat[j], inflation, n_data)
    ends, closed = [], True
    for side in (-1.0, 1.0):
        limit = bounds[0][j] if side < 0 else bounds[1][j]
        points, roots = [x_hat[j]], [0.0]
        for k in (1.0, 2.0):
            value = x_hat[j] + side * k * target * std
            if side * (value - limit) > 0:
                value = limit
            rise = _constrained_deviance(residuals, x_hat, jacobian, j, value, inflation, n_data)
            points.append(value)
            roots.append(np.sqrt(max(rise - base, 0.0)))
            if roots[-1] >= target or value == limit:
                break
        roots, points = np.array(roots), np.array(points)
        if roots[-1] >= target:
            end = np.interp(target, roots, points) if np.all(np.diff(roots) > 0) else points[-1]
        else:
            run = abs(points[-1] - points[-2])
            slope = (roots[-1] - roots[-2]) / run if run > 0 else 0.0
            reach = (target - roots[-1]) / slope if slope > 0 else np.inf
            end = points[-1] + side * reach
            if side * (end - limit) > 0:
                end, closed = limit, False
        ends.append(float(end))
    return Profile(name, level, ends[0] + offset, ends[1] + offset, closed)
