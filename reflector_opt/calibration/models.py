"""Calibration models: two sensor voltages -> pitch and roll of one unit.

Each model is a polynomial in the two voltages (v1, v2), one row of coefficients per angle,
with the scikit-learn estimator contract: ``__init__`` stores parameters, :meth:`fit`
learns and returns ``self``, learned attributes end in ``_``, :meth:`predict` maps new
voltages. Angles are ordered **(pitch, roll)** on every array axis and in every file.

- :class:`Eq5` — Osman et al. (2024) Eq 5, a linear 2×2 map with no intercept:
  [α, γ] = K [i1, i2]. The paper writes roll α first; here the pitch row is (k3, k4) and the
  roll row (k1, k2) (see :meth:`Eq5.paper_coefficients`).
- :class:`Eq6` — Osman et al. (2024) Eq 6, eight terms per angle in the paper's order
  γ = k1·v1 + k2·v2 + k3·v1² + k4·v2² + k5·v1·v2 + k6·v1·v2² + k7·v2·v1² + k8, and the same
  with j1…j8 for α.
- :class:`Polynomial` — every monomial v1^a·v2^b with a + b ≤ degree.

Fits (``fit=``): ``"lsq"`` ordinary least squares (LAPACK via :func:`numpy.linalg.lstsq`);
``"huber"`` the Huber loss (quadratic within a threshold, linear beyond; robust to outliers);
``"minimax"`` the smallest maximum absolute error (a linear programme). The last two are solved
with cvxpy; a solver that does not report an optimal solution raises
:class:`~reflector_opt.util.errors.FitError`. The minimax programme is solved by constraint
exchange: the LP on a working set of samples gives a lower bound on the optimum, the worst
samples of the full set are added until every sample lies within the bound (to 1e-6°), which
certifies the result optimal for the full set.

For conditioning, each voltage is centred and scaled to [-1, 1] before fitting; the term sets
of Eq 6 and of the full polynomials are closed under that change of variable, so the
coefficients are converted back exactly and reported in raw-voltage form (``coef_``). Eq 5
has no constant term, so its inputs are only scaled, never centred.
"""

from __future__ import annotations

import math

import numpy as np

from reflector_opt.util.errors import FitError, InputError
from reflector_opt.util.fileio import read_json, write_json

__all__ = [
    "ANGLES",
    "FITS",
    "MODEL_FORMAT",
    "Eq5",
    "Eq6",
    "Polynomial",
    "cross_validate",
    "load_model",
    "make_model",
    "model_from_dict",
]

ANGLES = ("pitch_deg", "roll_deg")
FITS = ("lsq", "huber", "minimax")
MODEL_FORMAT = "reflector-opt/calibration-model@1"
MAX_DEGREE = 10

# Singular values below this fraction of the largest count as zero: the voltages do not
# determine the coefficients.
_RANK_RTOL = 1e-10
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
_DEFAULT_SOLVERS = {"huber": ("OSQP", "CLARABEL"), "minimax": ("HIGHS", "CLARABEL")}


# --- monomials and the change of variable --------------------------------------------------------


def term_name(exponents):
    """Readable name of the monomial v1^a·v2^b, e.g. ``"v1^2*v2"``; ``"1"`` for the constant."""
    parts = [f"v{i + 1}" + (f"^{e}" if e > 1 else "") for i, e in enumerate(exponents) if e > 0]
    return "*".join(parts) or "1"


def monomials(volts, terms):
    """Evaluate monomials v1^a·v2^b.

    Parameters
    ----------
    volts : numpy.ndarray
        Shape ``P + (2,)``.
    terms : sequence of (int, int)
        Exponents (a, b) of each term.

    Returns
    -------
    numpy.ndarray
        Shape ``P + (n_terms,)``.
    """
    v1, v2 = volts[..., 0], volts[..., 1]
    return np.stack([v1**a * v2**b for a, b in terms], axis=-1)


def _substitute(coef, terms, slope, intercept):
    """Coefficients in w of Σ c_t·x^t after x_i = slope_i·w_i + intercept_i (binomial expansion).

    ``coef`` has shape (n_outputs, n_terms). Every term the expansion produces must be in
    ``terms`` (true for a set closed under lowering exponents, and for any set when the
    intercepts are zero).
    """
    index = {t: i for i, t in enumerate(terms)}
    out = np.zeros_like(coef)
    for col, (a, b) in enumerate(terms):
        for p in range(a + 1):
            for q in range(b + 1):
                factor = (
                    math.comb(a, p)
                    * math.comb(b, q)
                    * slope[0] ** p
                    * intercept[0] ** (a - p)
                    * slope[1] ** q
                    * intercept[1] ** (b - q)
                )
                if factor != 0.0:
                    out[:, index[(p, q)]] += factor * coef[:, col]
    return out


def _is_closed(terms):
    """True if lowering any exponent of a term gives another term of the set."""
    present = set(terms)
    return all((p, q) in present for a, b in terms for p in range(a + 1) for q in range(b + 1))


# --- input checks -------------------------------------------------------------------------------


def _samples(values, what):
    array = np.asarray(values, dtype=float)
    if array.ndim != 2 or array.shape[1] != 2:
        raise InputError(f"{what}: expected shape (n_samples, 2), got {array.shape}")
    bad = ~np.isfinite(array).all(axis=1)
    if bad.any():
        raise InputError(f"{what}: sample {int(np.flatnonzero(bad)[0])} is not finite")
    return array


# --- the solvers ----------------------------------------------------------------------------------


def _lstsq(X, Y, what):
    coef, _, _, singular = np.linalg.lstsq(X, Y, rcond=None)
    rank = int(np.sum(singular > _RANK_RTOL * singular[0])) if singular.size else 0
    if rank < X.shape[1]:
        raise FitError(
            f"{what}: the voltages do not determine the {X.shape[1]} coefficients "
            f"(design matrix rank {rank}); the samples must span the workspace"
        )
    return coef


def _solve(problem, solvers, what):
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


def _robust_scale(residual):
    """Normalised median absolute deviation of each column (σ for Gaussian residuals)."""
    centred = residual - np.median(residual, axis=0)
    return 1.4826 * np.median(np.abs(centred), axis=0)


def _huber_column(X, y, threshold, start, solvers, what):
    """Minimise Σ huber((X k − y) / threshold) exactly, with a small cvxpy problem per round.

    Samples whose residual is clearly inside the threshold enter through their least-squares
    normal equations (an n×n triangular factor), samples clearly outside through a linear
    term, and only the uncertain rest as explicit Huber terms. At the solution every sample's
    assumed region is checked; wrong ones become explicit and the problem is solved again.
    When all hold, the gradient of the full Huber objective vanishes: the result is optimal.
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
        used = _solve(cp.Problem(cp.Minimize(objective)), solvers, what)
        residual = Xs @ k.value - ys
        wrong = (quadratic & (np.abs(residual) > 1.0 + _EXCHANGE_TOL)) | (
            linear & (sign * residual < 1.0 - _EXCHANGE_TOL)
        )
        if not wrong.any():
            return k.value, used
        quadratic &= ~wrong
        linear &= ~wrong
    raise FitError(f"{what}: the exchange did not converge in {_EXCHANGE_ROUNDS} rounds")


def _minimax_column(X, y, start, solvers, what):
    """Minimise max |X k − y| by constraint exchange; the result is certified on all rows."""
    import cvxpy as cp

    m, n = X.shape
    residual = np.abs(X @ start - y)
    spread = np.linspace(0, m - 1, min(m, 50 * n)).astype(int)
    work = np.union1d(spread, np.argsort(residual)[-2 * n :])
    for _ in range(_EXCHANGE_ROUNDS):
        k, t = cp.Variable(n), cp.Variable()
        r = X[work] @ k - y[work]
        used = _solve(cp.Problem(cp.Minimize(t), [r <= t, -r <= t]), solvers, what)
        residual = np.abs(X @ k.value - y)
        limit = float(t.value) + _EXCHANGE_TOL * (1.0 + abs(float(t.value)))
        violators = np.flatnonzero(residual > limit)
        if violators.size == 0:
            return k.value, used
        worst = violators[np.argsort(residual[violators])[-5 * n :]]
        work = np.union1d(work, worst)
    raise FitError(f"{what}: the exchange did not converge in {_EXCHANGE_ROUNDS} rounds")


# --- the models -----------------------------------------------------------------------------------


class _PolynomialCalibration:
    """Shared machinery: a polynomial in (v1, v2) per angle, fitted in scaled inputs."""

    name = ""

    def __init__(self, *, fit="lsq", huber_threshold_deg=None, solver=None):
        self.fit_method = fit
        self.huber_threshold_deg = huber_threshold_deg
        self.solver = solver

    # -- what a subclass defines --

    @property
    def terms(self):
        """Exponents (a, b) of each term v1^a·v2^b, in coefficient order."""
        raise NotImplementedError

    def _extra_params(self):
        return {}

    # -- parameters --

    @property
    def centred(self):
        """Whether inputs are centred before fitting (only when the term set allows it)."""
        return _is_closed(self.terms)

    @property
    def term_names(self):
        """Readable names of the terms, in coefficient order."""
        return [term_name(t) for t in self.terms]

    def get_params(self):
        """Constructor parameters, as a dict (scikit-learn style)."""
        return {
            **self._extra_params(),
            "fit": self.fit_method,
            "huber_threshold_deg": self.huber_threshold_deg,
            "solver": self.solver,
        }

    def clone(self):
        """An unfitted copy with the same parameters."""
        return type(self)(**self.get_params())

    def __repr__(self):
        params = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({params})"

    def _check_params(self):
        if self.fit_method not in FITS:
            raise InputError(f"unknown fit {self.fit_method!r}; choose one of {', '.join(FITS)}")
        if self.huber_threshold_deg is not None and not self.huber_threshold_deg > 0:
            raise InputError(
                f"huber_threshold_deg: must be positive, got {self.huber_threshold_deg}"
            )

    # -- fitting --

    def fit(self, voltages, angles):
        """Learn the coefficients from calibration samples.

        Parameters
        ----------
        voltages : array_like
            Shape (n_samples, 2): v1, v2 of each sample, V (any two sensor signals work).
        angles : array_like
            Shape (n_samples, 2): true pitch and roll of each sample, degrees.

        Returns
        -------
        self
            With ``coef_`` (2, n_terms) raw-voltage coefficients (rows pitch, roll; columns
            :attr:`term_names`), ``centre_v_``/``scale_v_`` the input normalisation,
            ``n_samples_``, ``solver_`` (None for least squares), ``huber_threshold_deg_``
            (Huber only) and ``training_rms_deg_``/``training_max_deg_`` (pitch, roll).

        Raises
        ------
        InputError
            Bad shapes or non-finite samples, fewer samples than coefficients, all samples
            at one pose.
        FitError
            The voltages do not determine the coefficients, or the solver failed.
        """
        self._check_params()
        V = _samples(voltages, "voltages")
        A = _samples(angles, "angles")
        n_terms = len(self.terms)
        what = f"{self.name} {self.fit_method} fit"
        if len(V) != len(A):
            raise InputError(f"{what}: {len(V)} voltage samples but {len(A)} angle samples")
        if len(V) < n_terms:
            raise InputError(
                f"{what}: {len(V)} samples are fewer than the {n_terms} coefficients per angle"
            )
        if np.all(A == A[0]):
            raise InputError(
                f"{what}: every sample has the same pose (pitch {A[0, 0]:g}°, roll "
                f"{A[0, 1]:g}°); calibration needs samples over the workspace"
            )
        lo, hi = V.min(axis=0), V.max(axis=0)
        if self.centred:
            centre, scale = (hi + lo) / 2.0, (hi - lo) / 2.0
        else:
            centre, scale = np.zeros(2), np.abs(V).max(axis=0)
        scale = np.where(scale > 0, scale, 1.0)
        X = monomials((V - centre) / scale, self.terms)
        coef = _lstsq(X, A, what)
        solver_used = None
        if self.fit_method == "huber":
            if self.huber_threshold_deg is None:
                threshold = np.maximum(_HUBER_K * _robust_scale(X @ coef - A), _HUBER_FLOOR_DEG)
            else:
                threshold = np.full(2, float(self.huber_threshold_deg))
            self.huber_threshold_deg_ = threshold
        if self.fit_method != "lsq":
            columns = [
                self._refine(X, A[:, j], coef[:, j], j, f"{what} ({ANGLES[j]})") for j in range(2)
            ]
            coef = np.stack([c for c, _ in columns], axis=1)
            solver_used = columns[-1][1]
        self._set_fitted(coef.T, centre, scale, len(V), solver_used)
        error = X @ coef - A
        self.training_rms_deg_ = np.sqrt(np.mean(error**2, axis=0))
        self.training_max_deg_ = np.abs(error).max(axis=0)
        return self

    def _refine(self, X, y, start, column, what):
        if self.fit_method == "huber":
            threshold = self.huber_threshold_deg_[column]
            return _huber_column(X, y, threshold, start, self._solvers(), what)
        return _minimax_column(X, y, start, self._solvers(), what)

    def _solvers(self):
        return (self.solver,) if self.solver else _DEFAULT_SOLVERS[self.fit_method]

    def _set_fitted(self, coef_scaled, centre, scale, n_samples, solver):
        self._coef_scaled = np.asarray(coef_scaled, dtype=float)
        self.centre_v_ = np.asarray(centre, dtype=float)
        self.scale_v_ = np.asarray(scale, dtype=float)
        self.coef_ = _substitute(self._coef_scaled, self.terms, 1.0 / scale, -centre / scale)
        self.n_samples_ = int(n_samples)
        self.solver_ = solver

    # -- prediction --

    def _check_fitted(self):
        if not hasattr(self, "coef_"):
            raise InputError(f"{type(self).__name__} is not fitted; call fit() first")

    def predict(self, voltages):
        """Pitch and roll from sensor voltages.

        Parameters
        ----------
        voltages : array_like
            Shape ``P + (2,)``, V.

        Returns
        -------
        numpy.ndarray
            Shape ``P + (2,)``: pitch, roll in degrees.
        """
        self._check_fitted()
        V = np.asarray(voltages, dtype=float)
        if V.shape[-1:] != (2,):
            raise InputError(f"voltages: the last axis must hold v1, v2, got shape {V.shape}")
        return monomials((V - self.centre_v_) / self.scale_v_, self.terms) @ self._coef_scaled.T

    # -- JSON --

    def to_dict(self):
        """JSON-ready dict of the parameters and the fitted coefficients (raw-voltage form)."""
        self._check_fitted()
        out = {
            "format": MODEL_FORMAT,
            "model": self.name,
            "params": self.get_params(),
            "inputs": ["v1", "v2"],
            "terms": self.term_names,
            "coefficients": {a: self.coef_[i].tolist() for i, a in enumerate(ANGLES)},
            "input_centre_v": self.centre_v_.tolist(),
            "input_scale_v": self.scale_v_.tolist(),
            "n_samples": self.n_samples_,
            "solver": self.solver_,
            "training": {
                "rms_deg": dict(zip(ANGLES, self.training_rms_deg_.tolist(), strict=True)),
                "max_deg": dict(zip(ANGLES, self.training_max_deg_.tolist(), strict=True)),
            },
        }
        if hasattr(self, "huber_threshold_deg_"):
            out["huber_threshold_deg"] = self.huber_threshold_deg_.tolist()
        return out

    def save(self, path):
        """Write :meth:`to_dict` as JSON, atomically."""
        write_json(path, self.to_dict())


class Eq5(_PolynomialCalibration):
    """Osman et al. (2024) Eq 5: pitch and roll linear in the two signals.

    pitch = k3·v1 + k4·v2, roll = k1·v1 + k2·v2 (the paper's [α, γ] = K·[i1, i2]; no
    intercept). A map through the origin cannot send the nonzero zero-pose readings to zero
    angles, so ``intercept=True`` adds a constant per angle (an affine map) for comparison.

    Parameters
    ----------
    fit : {"lsq", "huber", "minimax"}
    intercept : bool
        Add a constant term (not in the paper).
    huber_threshold_deg : float, optional
        Huber threshold, degrees; default 1.345 × the residuals' robust scale.
    solver : str, optional
        cvxpy solver name; default OSQP then Clarabel (Huber), HiGHS then Clarabel (minimax).
    """

    name = "eq5"

    def __init__(self, *, fit="lsq", intercept=False, huber_threshold_deg=None, solver=None):
        super().__init__(fit=fit, huber_threshold_deg=huber_threshold_deg, solver=solver)
        self.intercept = intercept

    @property
    def terms(self):
        return ((1, 0), (0, 1), (0, 0)) if self.intercept else ((1, 0), (0, 1))

    def _extra_params(self):
        return {"intercept": self.intercept}

    def _check_params(self):
        super()._check_params()
        if not isinstance(self.intercept, bool):
            raise InputError(f"intercept: must be true or false, got {self.intercept!r}")

    def paper_coefficients(self):
        """The fitted k1…k4 of the paper's Eq 5 (k1, k2 roll; k3, k4 pitch)."""
        self._check_fitted()
        (k3, k4, *_), (k1, k2, *_) = self.coef_
        return {"k1": k1, "k2": k2, "k3": k3, "k4": k4}


class Eq6(_PolynomialCalibration):
    """Osman et al. (2024) Eq 6: eight terms per angle in the paper's order.

    pitch γ = k1·v1 + k2·v2 + k3·v1² + k4·v2² + k5·v1·v2 + k6·v1·v2² + k7·v2·v1² + k8;
    roll α the same with j1…j8.

    Parameters
    ----------
    fit : {"lsq", "huber", "minimax"}
    huber_threshold_deg : float, optional
        Huber threshold, degrees; default 1.345 × the residuals' robust scale.
    solver : str, optional
        cvxpy solver name; default OSQP then Clarabel (Huber), HiGHS then Clarabel (minimax).
    """

    name = "eq6"
    _TERMS = ((1, 0), (0, 1), (2, 0), (0, 2), (1, 1), (1, 2), (2, 1), (0, 0))

    @property
    def terms(self):
        return self._TERMS

    def paper_coefficients(self):
        """The fitted k1…k8 (pitch) and j1…j8 (roll) of the paper's Eq 6."""
        self._check_fitted()
        pitch, roll = self.coef_
        return {
            **{f"k{i + 1}": float(c) for i, c in enumerate(pitch)},
            **{f"j{i + 1}": float(c) for i, c in enumerate(roll)},
        }


class Polynomial(_PolynomialCalibration):
    """Full polynomial of total degree ``degree`` in (v1, v2) per angle.

    Terms v1^a·v2^b with a + b ≤ degree, ordered by total degree, then by falling power of v1;
    (degree + 1)(degree + 2)/2 coefficients per angle.

    Parameters
    ----------
    degree : int
        Total degree, 1 to 10.
    fit : {"lsq", "huber", "minimax"}
    huber_threshold_deg : float, optional
    solver : str, optional
    """

    def __init__(self, degree=3, *, fit="lsq", huber_threshold_deg=None, solver=None):
        super().__init__(fit=fit, huber_threshold_deg=huber_threshold_deg, solver=solver)
        self.degree = degree

    @property
    def name(self):
        return f"poly{self.degree}"

    @property
    def terms(self):
        return tuple((d - b, b) for d in range(self.degree + 1) for b in range(d + 1))

    def _check_params(self):
        super()._check_params()
        if isinstance(self.degree, bool) or self.degree not in range(1, MAX_DEGREE + 1):
            raise InputError(
                f"poly{self.degree}: the degree must be a whole number from 1 to {MAX_DEGREE}"
            )

    def _extra_params(self):
        return {"degree": self.degree}


# --- construction by name, JSON ------------------------------------------------------------------


def make_model(name, fit="lsq", **params):
    """A calibration model from its name.

    Parameters
    ----------
    name : str
        ``"eq5"``, ``"eq6"`` or ``"polyN"`` (N = 1 … 10).
    fit : {"lsq", "huber", "minimax"}
    **params
        Further constructor parameters (``intercept``, ``huber_threshold_deg``, ``solver``).

    Returns
    -------
    Eq5, Eq6 or Polynomial
    """
    text = str(name).strip().lower()
    if text == "eq5":
        model = Eq5(fit=fit, **params)
    elif text == "eq6":
        model = Eq6(fit=fit, **params)
    elif text.startswith("poly") and text[4:].isdigit():
        model = Polynomial(int(text[4:]), fit=fit, **params)
    else:
        raise InputError(f"unknown model {name!r}; choose eq5, eq6 or polyN (N = 1 to 10)")
    model._check_params()
    return model


def _floats(value, length, where):
    if not isinstance(value, list) or len(value) != length:
        raise InputError(f"{where}: expected a list of {length} numbers")
    if not all(isinstance(v, int | float) and not isinstance(v, bool) for v in value):
        raise InputError(f"{where}: expected numbers")
    array = np.array(value, dtype=float)
    if not np.isfinite(array).all():
        raise InputError(f"{where}: numbers must be finite")
    return array


def model_from_dict(data, where="calibration"):
    """Rebuild a fitted model from :meth:`to_dict` output; errors name the field.

    Parameters
    ----------
    data : dict
    where : str
        Prefix for error messages.

    Returns
    -------
    Eq5, Eq6 or Polynomial
    """
    if not isinstance(data, dict):
        raise InputError(f"{where}: expected an object")
    for key in ("model", "coefficients", "input_centre_v", "input_scale_v"):
        if key not in data:
            raise InputError(f"{where}.{key}: missing key")
    params = dict(data.get("params") or {})
    if not isinstance(params, dict):
        raise InputError(f"{where}.params: expected an object")
    fit = params.pop("fit", "lsq")
    degree = params.pop("degree", None)
    try:
        model = make_model(data["model"], fit, **params)
    except TypeError as exc:
        raise InputError(f"{where}.params: {exc}") from None
    if degree is not None and degree != getattr(model, "degree", None):
        raise InputError(f"{where}.params.degree: {degree!r} does not match {model.name}")
    n_terms = len(model.terms)
    if "terms" in data and data["terms"] != model.term_names:
        raise InputError(f"{where}.terms: expected {model.term_names}")
    coefficients = data["coefficients"]
    if not isinstance(coefficients, dict):
        raise InputError(f"{where}.coefficients: expected an object with {', '.join(ANGLES)}")
    raw = np.stack(
        [_floats(coefficients.get(a), n_terms, f"{where}.coefficients.{a}") for a in ANGLES]
    )
    centre = _floats(data["input_centre_v"], 2, f"{where}.input_centre_v")
    scale = _floats(data["input_scale_v"], 2, f"{where}.input_scale_v")
    if not (scale > 0).all():
        raise InputError(f"{where}.input_scale_v: must be positive")
    if not model.centred and centre.any():
        raise InputError(f"{where}.input_centre_v: must be zero for {model.name}")
    model._set_fitted(
        _substitute(raw, model.terms, scale, centre),
        centre,
        scale,
        data.get("n_samples", 0),
        data.get("solver"),
    )
    training = data.get("training") or {}
    for attr, key in (("training_rms_deg_", "rms_deg"), ("training_max_deg_", "max_deg")):
        block = training.get(key)
        if isinstance(block, dict) and all(a in block for a in ANGLES):
            setattr(model, attr, np.array([float(block[a]) for a in ANGLES]))
    if "huber_threshold_deg" in data:
        model.huber_threshold_deg_ = _floats(
            data["huber_threshold_deg"], 2, f"{where}.huber_threshold_deg"
        )
    return model


def load_model(path):
    """Read a model written by ``save``.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    Eq5, Eq6 or Polynomial
    """
    data = read_json(path)
    if not isinstance(data, dict) or data.get("format") != MODEL_FORMAT:
        raise InputError(f"{path}: not a calibration model (format {MODEL_FORMAT!r})")
    return model_from_dict(data, str(path))


# --- cross-validation -----------------------------------------------------------------------------


def cross_validate(model, voltages, angles, folds=5, seed=0):
    """K-fold cross-validated error of a calibration model.

    Samples are shuffled (seeded) into ``folds`` groups; each group is predicted by a copy
    of ``model`` fitted on the others. The statistics pool every held-out prediction.

    Parameters
    ----------
    model : Eq5, Eq6 or Polynomial
        Used as a template (not modified).
    voltages, angles : array_like
        Shape (n_samples, 2) each: V; pitch, roll in degrees.
    folds : int
        Number of folds, at least 2.
    seed : int
        Seed of the shuffle.

    Returns
    -------
    dict
        ``rms_deg`` and ``max_deg``: arrays (pitch, roll), degrees; ``folds``.
    """
    V = _samples(voltages, "voltages")
    A = _samples(angles, "angles")
    if isinstance(folds, bool) or int(folds) != folds or folds < 2:
        raise InputError(f"folds: must be a whole number of at least 2, got {folds}")
    if folds > len(V):
        raise InputError(f"folds: {folds} folds need at least {folds} samples, got {len(V)}")
    order = np.random.default_rng(seed).permutation(len(V))
    predicted = np.empty_like(A)
    for i, held_out in enumerate(np.array_split(order, int(folds))):
        train = np.setdiff1d(order, held_out)
        try:
            fitted = model.clone().fit(V[train], A[train])
        except InputError as exc:
            raise type(exc)(f"cross-validation fold {i + 1} of {folds}: {exc}") from None
        predicted[held_out] = fitted.predict(V[held_out])
    error = predicted - A
    return {
        "rms_deg": np.sqrt(np.mean(error**2, axis=0)),
        "max_deg": np.abs(error).max(axis=0),
        "folds": int(folds),
    }
