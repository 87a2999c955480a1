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

Losses (``loss=``, named ``fit=`` before: deprecated): ``"lsq"`` least squares, ``"huber"``
the Huber loss, ``"minimax"`` the smallest maximum absolute error
(:mod:`~reflector_opt.calibration._fitting`).

For conditioning, each voltage is centred and scaled to [-1, 1] before fitting; the term sets
of Eq 6 and of the full polynomials are closed under that change of variable, so the
coefficients are converted back exactly (:mod:`~reflector_opt.calibration._terms`) and reported
in raw-voltage form (``coef_``). Eq 5 has no constant term, so its inputs are only scaled,
never centred.

Coefficient files: :mod:`~reflector_opt.calibration._coefficients`; cross-validation:
:mod:`~reflector_opt.calibration._validation`.
"""

import functools
import inspect
import warnings

import numpy as np

from reflector_opt.calibration._fitting import check_method, fit_coefficients
from reflector_opt.calibration._terms import (
    input_normalisation,
    is_closed,
    monomials,
    term_name,
    to_raw,
    to_scaled,
)
from reflector_opt.util._errors import InputError

ANGLES = ("pitch_deg", "roll_deg")
MAX_DEGREE = 10


def check_samples(values, what):
    """``values`` as a float array of shape (n_samples, 2) with finite rows; else InputError."""
    array = np.asarray(values, dtype=float)
    if array.ndim != 2 or array.shape[1] != 2:
        raise InputError(f"{what}: expected shape (n_samples, 2), got {array.shape}")
    bad = ~np.isfinite(array).all(axis=1)
    if bad.any():
        raise InputError(f"{what}: sample {int(np.flatnonzero(bad)[0])} is not finite")
    return array


def check_sample_pairs(voltages, angles, what):
    """Voltages and reference angles checked by :func:`check_samples`, as many of each.

    Parameters
    ----------
    voltages, angles : array_like
        Shape (n_samples, 2): V and degrees.
    what : str
        The model, for the message.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
    """
    V, A = check_samples(voltages, "voltages"), check_samples(angles, "angles")
    if len(V) != len(A):
        raise InputError(f"{what}: {len(V)} voltage samples but {len(A)} angle samples")
    return V, A


def _training_data(voltages, angles, n_terms, what):
    """Checked training arrays (n_samples, 2) each: enough samples, not all at one pose."""
    V, A = check_sample_pairs(voltages, angles, what)
    if len(V) < n_terms:
        raise InputError(
            f"{what}: {len(V)} samples are fewer than the {n_terms} coefficients per angle"
        )
    if np.all(A == A[0]):
        raise InputError(
            f"{what}: every sample has the same pose (pitch {A[0, 0]:g}°, roll "
            f"{A[0, 1]:g}°); calibration needs samples over the workspace"
        )
    return V, A


def _rms_and_max(error):
    """RMS and largest absolute value of each column of ``error``."""
    return np.sqrt(np.mean(error**2, axis=0)), np.abs(error).max(axis=0)


def _both_forms(terms, centre, scale, coef_scaled=None, coef=None):
    """Coefficients in scaled-input and raw form from the one given (scaled if ``coef`` is
    None): that one is kept exactly, the other derived from it."""
    if coef is None:
        coef_scaled = np.asarray(coef_scaled, dtype=float)
        return coef_scaled, to_raw(coef_scaled, terms, centre, scale)
    coef = np.asarray(coef, dtype=float)
    return to_scaled(coef, terms, centre, scale), coef


#: Constructor parameters renamed, by their old names: ``fit`` hid the ``fit`` method.
RENAMED = {"fit": "loss"}


def _taking_old_names(init):
    """``init`` taking a renamed parameter by its old name (:data:`RENAMED`): for one release
    with a FutureWarning where the class still takes it (docs/calibration.md and the example
    notebook wrote ``Eq5(fit=...)``, ``Eq6(fit=...)``), else refused with an InputError naming
    the new name. Its signature is ``init``'s, which scikit-learn reads."""

    @functools.wraps(init)
    def __init__(self, *args, **params):
        for old in RENAMED.keys() & params.keys():
            what, new = type(self).__name__, RENAMED[old]
            if not self._old_names_taken:
                raise InputError(f"{old}: renamed {new} (it hid the method); pass {what}({new}=)")
            message = f"{what}({old}=...) is renamed {what}({new}=...); {old}= goes next release"
            warnings.warn(message, FutureWarning, stacklevel=2)
            params[new] = params.pop(old)
        init(self, *args, **params)

    return __init__


def recorded_params(model):
    """``model``'s constructor parameters as its files and ``--json`` record them: ``loss``
    under its old key ``fit`` (the files' keys are unchanged)."""
    old = {new: name for name, new in RENAMED.items()}
    return {old.get(k, k): v for k, v in model.get_params(deep=False).items()}


class Estimator:
    """What every calibration model shares, scikit-learn's estimator contract: the
    constructor stores each parameter under its own name and does nothing else, so that
    :meth:`get_params`, :meth:`set_params` and scikit-learn's ``clone`` hold; an unfitted
    copy and a ``repr`` come from them."""

    #: Whether the constructor still takes a renamed parameter's old name (one release).
    _old_names_taken = False

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "__init__" in vars(cls) and set(RENAMED.values()) & set(cls._param_names()):
            cls.__init__ = _taking_old_names(cls.__init__)

    @classmethod
    def _param_names(cls):
        """The constructor's named parameters, in its order."""
        kinds = (inspect.Parameter.VAR_KEYWORD, inspect.Parameter.VAR_POSITIONAL)
        return [p.name for p in inspect.signature(cls).parameters.values() if p.kind not in kinds]

    def get_params(self, deep=True):
        """Constructor parameters, as a dict (scikit-learn's ``get_params``).

        Parameters
        ----------
        deep : bool
            Also the parameters of a parameter that is an estimator, as ``name__param``.

        Returns
        -------
        dict
        """
        out = {}
        for name in self._param_names():
            value = getattr(self, name)
            if deep and isinstance(value, Estimator):
                out |= {f"{name}__{k}": v for k, v in value.get_params().items()}
            out[name] = value
        return out

    def set_params(self, **params):
        """Set constructor parameters (``name__param`` for a parameter's own); returns self.

        Raises
        ------
        InputError
            A name that is not a parameter (a renamed one names its new name).
        """
        names = self._param_names()
        for key, value in params.items():
            name, _, inner = key.partition("__")
            if name not in names:
                known = f"renamed {RENAMED[name]}" if name in RENAMED else ", ".join(names)
                raise InputError(f"{key}: not a parameter of {type(self).__name__} ({known})")
            if inner:
                getattr(self, name).set_params(**{inner: value})
            else:
                setattr(self, name, value)
        return self

    def _check_fitted(self):
        """InputError unless :meth:`fit` (or a file) set the learned attributes
        (``n_samples_``, set last)."""
        if not hasattr(self, "n_samples_"):
            raise InputError(f"{type(self).__name__} is not fitted; call fit() first")

    def clone(self):
        """An unfitted copy with the same parameters."""
        return type(self)(**self.get_params(deep=False))

    def __repr__(self):
        params = ", ".join(f"{k}={v!r}" for k, v in self.get_params(deep=False).items())
        return f"{type(self).__name__}({params})"


class _PolynomialCalibration(Estimator):
    """Shared machinery: a polynomial in (v1, v2) per angle, fitted in scaled inputs."""

    name = ""
    _old_names_taken = True

    def __init__(self, *, loss="lsq", huber_threshold_deg=None, solver=None):
        self.loss = loss
        self.huber_threshold_deg = huber_threshold_deg
        self.solver = solver

    @property
    def terms(self):
        """Exponents (a, b) of each term v1^a·v2^b, in coefficient order (set by a subclass)."""
        raise NotImplementedError

    @property
    def centred(self):
        """Whether inputs are centred before fitting (only when the term set allows it)."""
        return is_closed(self.terms)

    @property
    def term_names(self):
        """Readable names of the terms, in coefficient order."""
        return [term_name(t) for t in self.terms]

    def _check_params(self):
        check_method(self.loss, self.huber_threshold_deg)

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
        what = f"{self.name} {self.loss} fit"
        V, A = _training_data(voltages, angles, len(self.terms), what)
        centre, scale = input_normalisation(V, self.centred)
        X = monomials((V - centre) / scale, self.terms)
        result = fit_coefficients(
            X, A, self.loss, what, self.huber_threshold_deg, self.solver, ANGLES
        )
        self._set_fitted(centre, scale, len(V), result.solver, coef_scaled=result.coef.T)
        if result.threshold is not None:
            self.huber_threshold_deg_ = result.threshold
        self.training_rms_deg_, self.training_max_deg_ = _rms_and_max(X @ result.coef - A)
        return self

    def _set_fitted(self, centre, scale, n_samples, solver, *, coef_scaled=None, coef=None):
        """Store coefficients in scaled-input (a fit) or raw form (a file); that form is kept
        exactly, the other derived from it (exact up to round-off)."""
        self.centre_v_, self.scale_v_ = (np.asarray(v, dtype=float) for v in (centre, scale))
        self._coef_scaled, self.coef_ = _both_forms(
            self.terms, self.centre_v_, self.scale_v_, coef_scaled, coef
        )
        self.n_samples_ = int(n_samples)
        self.solver_ = solver

    @property
    def scaled_coef_(self):
        """The coefficients in the scaled inputs, shape (2, n_terms): what :meth:`predict`
        evaluates, on ``(V - centre_v_) / scale_v_``."""
        return self._coef_scaled

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


class Eq5(_PolynomialCalibration):
    """Osman et al. (2024) Eq 5: pitch and roll linear in the two signals.

    pitch = k3·v1 + k4·v2, roll = k1·v1 + k2·v2 (the paper's [α, γ] = K·[i1, i2]; no
    intercept). A map through the origin cannot send the nonzero zero-pose readings to zero
    angles, so ``intercept=True`` adds a constant per angle (an affine map) for comparison.

    Parameters
    ----------
    loss : {"lsq", "huber", "minimax"}
        The fit's loss (module notes; the old name ``fit=`` is deprecated).
    intercept : bool
        Add a constant term (not in the paper).
    huber_threshold_deg : float, optional
        Huber threshold, degrees; default 1.345 × the residuals' robust scale.
    solver : str, optional
        cvxpy solver name; default OSQP then Clarabel (Huber), HiGHS then Clarabel (minimax).
    """

    name = "eq5"

    def __init__(self, *, loss="lsq", intercept=False, huber_threshold_deg=None, solver=None):
        super().__init__(loss=loss, huber_threshold_deg=huber_threshold_deg, solver=solver)
        self.intercept = intercept

    @property
    def terms(self):
        return ((1, 0), (0, 1), (0, 0)) if self.intercept else ((1, 0), (0, 1))

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
    loss : {"lsq", "huber", "minimax"}
        The fit's loss (module notes; the old name ``fit=`` is deprecated).
    huber_threshold_deg : float, optional
        Huber threshold, degrees; default 1.345 × the residuals' robust scale.
    solver : str, optional
        cvxpy solver name; default OSQP then Clarabel (Huber), HiGHS then Clarabel (minimax).
    """

    name = "eq6"
    terms = ((1, 0), (0, 1), (2, 0), (0, 2), (1, 1), (1, 2), (2, 1), (0, 0))

    def paper_coefficients(self):
        """The fitted k1…k8 (pitch) and j1…j8 (roll) of the paper's Eq 6."""
        self._check_fitted()
        rows = zip("kj", self.coef_, strict=True)  # k: pitch, j: roll
        return {f"{k}{i + 1}": float(c) for k, row in rows for i, c in enumerate(row)}


class Polynomial(_PolynomialCalibration):
    """Full polynomial of total degree ``degree`` in (v1, v2) per angle.

    Terms v1^a·v2^b with a + b ≤ degree, ordered by total degree, then by falling power of v1;
    (degree + 1)(degree + 2)/2 coefficients per angle.

    Parameters
    ----------
    degree : int
        Total degree, 1 to 10.
    loss : {"lsq", "huber", "minimax"}
        The fit's loss (module notes; the old name ``fit=`` is deprecated).
    huber_threshold_deg : float, optional
    solver : str, optional
    """

    def __init__(self, degree=3, *, loss="lsq", huber_threshold_deg=None, solver=None):
        super().__init__(loss=loss, huber_threshold_deg=huber_threshold_deg, solver=solver)
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


def make_model(name, loss="lsq", **params):
    """A calibration model from its name.

    Parameters
    ----------
    name : str
        ``"eq5"``, ``"eq6"`` or ``"polyN"`` (N = 1 … 10).
    loss : {"lsq", "huber", "minimax"}
        The fit's loss (module notes; the old name ``fit=`` is deprecated).
    **params
        Further constructor parameters (``intercept``, ``huber_threshold_deg``, ``solver``).

    Returns
    -------
    Eq5, Eq6 or Polynomial
    """
    text = str(name).strip().lower()
    if text == "eq5":
        model = Eq5(loss=loss, **params)
    elif text == "eq6":
        model = Eq6(loss=loss, **params)
    elif text.startswith("poly") and text[4:].isdigit():
        model = Polynomial(int(text[4:]), loss=loss, **params)
    else:
        raise InputError(f"unknown model {name!r}; choose eq5, eq6 or polyN (N = 1 to 10)")
    model._check_params()
    return model
