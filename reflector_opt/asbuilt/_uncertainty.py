"""What the data say about the as-built parameters: covariance, determined combinations, profiles.

* **Covariance** (Laplace approximation at the MAP estimate): ``Σ = (J_dᵀ J_d / s² + Σ_p⁻¹)⁻¹``
  with J_d the Jacobian of the weighted data residuals and Σ_p the prior's diagonal
  covariance. s² ≥ 1 is the block cross-validation ratio (:func:`cross_validation_ratio`):
  how much worse than the noise the fit predicts each block of poses it is not given — a
  discrepancy smooth over the poses, which the nuisance parameters absorb in the sample
  (a white-noise Birge ratio stays at 1), shows when a region of the workspace must be
  predicted from the others. Whatever the inflation, Σ never exceeds Σ_p: the data only
  add information.
* **Gross misfit**: the Birge ratio, χ² per effective degree of freedom
  (:func:`birge_ratio`; the effective number of fitted parameters is the trace of the hat
  matrix), refuses data that cannot come from the design.
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

from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

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


def cross_validation_ratio(data_residuals, data_jacobian, prior_std, blocks):
    """s² = max(1, mean over the data of each held-out block's standardised prediction error).

    Leaving block b out of a linear(ised) Gaussian fit, its prediction error is
    ``e_b = (I − H_bb)⁻¹ r_b`` with variance ``(I − H_bb)⁻¹`` (in noise units), r_b the
    block's residuals of the full fit and ``H_bb = J_b Σ J_bᵀ`` its block of the hat matrix
    (Σ the posterior covariance without inflation); so ``Σ_b r_bᵀ (I − H_bb)⁻¹ r_b / n``
    is 1 on average when the model holds, and larger when the misfit of one region of the
    workspace cannot be predicted from the others. Exact for a linear model; one fit, no
    refits.

    Parameters
    ----------
    data_residuals : numpy.ndarray
        Weighted data residuals at the estimate, (n,).
    data_jacobian : numpy.ndarray
        (n, p).
    prior_std : numpy.ndarray
        (p,).
    blocks : numpy.ndarray
        (n,) integer block label of each residual (:func:`block_labels`).

    Returns
    -------
    float
    """
    covariance = posterior_covariance(data_jacobian, prior_std, 1.0)
    total = 0.0
    for label in np.unique(blocks):
        rows = blocks == label
        J = data_jacobian[rows]
        hat = J @ covariance @ J.T
        r = data_residuals[rows]
        total += float(r @ np.linalg.solve(np.eye(len(r)) - hat, r))
    return max(1.0, total / len(data_residuals))


def block_labels(angles_deg, n_sensors, tiles=3):
    """Block label of each calibration residual: its pose's tile of the workspace.

    The poses are cut into ``tiles`` × ``tiles`` tiles at the terciles (for 3) of their
    pitch and of their roll; every sensor's residual of a pose shares the pose's tile.

    Parameters
    ----------
    angles_deg : numpy.ndarray
        (n, 2) poses, degrees.
    n_sensors : int
    tiles : int

    Returns
    -------
    numpy.ndarray
        (n · n_sensors,) labels in 0 … tiles² − 1, in the order of the flattened (n, sensors)
        residuals.
    """
    edges = np.linspace(0.0, 1.0, tiles + 1)[1:-1]
    cells = [np.searchsorted(np.quantile(c, edges), c, side="right") for c in angles_deg.T]
    return np.repeat(cells[0] * tiles + cells[1], n_sensors)


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
    """A combination named in words by its main terms (:func:`direction_name`)."""
    vector = vector * np.sign(vector[np.argmax(np.abs(vector))])
    order = np.argsort(-np.abs(vector))
    weights = {
        names[i]: round(float(vector[i]), 4) for i in order if abs(vector[i]) >= _LISTED_WEIGHT
    }
    return Combination(direction_name(vector, names, words), weights, ratio)


def direction_name(weights, names, words):
    """A combination of parameters in plain words, largest terms first.

    Parameters
    ----------
    weights : numpy.ndarray
        Shape (g,): the direction in prior-std units.
    names : sequence of str
        The g parameter names.
    words : callable
        Name → plain words.

    Returns
    -------
    str
        E.g. ``"reflector centre z − sensor 1 standoff"``.
    """
    order = np.argsort(-np.abs(weights))
    terms = [i for i in order if abs(weights[i]) >= _NAMED_SHARE * abs(weights[order[0]])]
    sign = np.sign(weights[np.argmax(np.abs(weights))])
    text = words(names[terms[0]])
    for i in terms[1:_NAMED_TERMS]:
        text += f" {'+' if weights[i] * sign > 0 else '−'} {words(names[i])}"
    if len(terms) > _NAMED_TERMS:
        text += f" (and {len(terms) - _NAMED_TERMS} smaller terms)"
    return text


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
