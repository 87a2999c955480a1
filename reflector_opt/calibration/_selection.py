"""Choose a calibration model's form and order by cross-validation.

:class:`AutoModel` (``--model auto``) cross-validates every candidate form the data can fit
(:data:`CANDIDATES`: the paper's Eq 5 and Eq 6 and full polynomials of degree 1 to 8) and
keeps the **simplest within one standard error of the best** (the one-standard-error rule;
Hastie, Tibshirani and Friedman, *The Elements of Statistical Learning*, 2nd ed., §7.10):
the score of a form is its held-out mean squared error over both angles, its standard error
that of a mean of the pooled per-sample squared errors, and "simplest" means the fewest
coefficients per angle. The chosen form is then fitted to all the samples.

With least squares, the full polynomials are cross-validated together
(:func:`polynomial_cv_errors`): their terms are ordered by total degree, so the terms of degree
d are the leading columns of those of degree 8, and one QR factorisation X = QR of a fold's
training matrix gives every degree's fit — the least-squares coefficients of the first p
columns solve R[:p, :p] c = (Qᵀy)[:p] (Golub and Van Loan, *Matrix Computations*, 4th ed.,
§5.3). The singular values of R[:p, :p] are those of the first p columns, so a rank-deficient
degree is recognised by the same rule as a single fit's
(:func:`~reflector_opt.calibration._fitting.lstsq`) and then cross-validated the ordinary way,
which reports it. The held-out errors are those of :func:`cross_validate` up to round-off
(tests/calibration/test_selection.py), at the cost of one factorisation per fold instead of
eight singular value decompositions.
"""

import numpy as np
from scipy.linalg import solve_triangular

from reflector_opt.calibration._fitting import RANK_RTOL as RANK_RTOL
from reflector_opt.calibration._models import (
    Estimator,
    Polynomial,
    check_sample_pairs,
    make_model,
)
from reflector_opt.calibration._terms import input_normalisation
from reflector_opt.calibration._validation import check_folds, cross_validate
from reflector_opt.util._errors import InputError

#: Forms :class:`AutoModel` chooses from.
CANDIDATES = ("eq5", "eq6", *(f"poly{d}" for d in range(1, 9)))

#: A form is a candidate only with at least this many samples per coefficient in every fold's
#: training set (fewer make the held-out error a poor guide).
SAMPLES_PER_TERM = 2


class AutoModel(Estimator):
    """The calibration form and order chosen by k-fold cross-validation.

    Parameters
    ----------
    loss : {"lsq", "huber", "minimax"}
        The fit's loss for every candidate (``fit=`` before: refused, naming ``loss``).
    folds : int
        Cross-validation folds, at least 2.
    seed : int
        Seed of the fold shuffle.
    candidates : sequence of str, optional
        Form names (:func:`~reflector_opt.calibration._models.make_model`); default
        :data:`CANDIDATES`.

    Attributes
    ----------
    selected_ : Eq5, Eq6 or Polynomial
        The chosen form, fitted to every sample (after :meth:`fit`).
    scores_ : list of dict
        Per candidate tried: ``model``, ``n_terms``, ``cv_rms_deg`` (pitch, roll), ``mse``
        and ``mse_se`` (deg², both angles pooled).
    n_samples_ : int
    """

    name = "auto"

    def __init__(self, *, loss="lsq", folds=5, seed=0, candidates=None):
        self.loss = loss
        self.folds = folds
        self.seed = seed
        self.candidates = candidates

    def fit(self, voltages, angles):
        """Cross-validate the candidates, choose one and fit it to every sample.

        Parameters
        ----------
        voltages : array_like
            Shape (n_samples, 2), V.
        angles : array_like
            Shape (n_samples, 2): reference pitch and roll, degrees.

        Returns
        -------
        self
        """
        V, A = check_sample_pairs(voltages, angles, "auto")
        folds = check_folds(self.folds)
        training = len(V) * (folds - 1) // folds
        names = [
            name
            for name in self.candidates or CANDIDATES
            if training >= SAMPLES_PER_TERM * len(make_model(name, self.loss).terms)
        ]
        nested = {}
        if self.loss == "lsq":
            degrees = [m.degree for m in map(make_model, names) if isinstance(m, Polynomial)]
            nested = polynomial_cv_errors(V, A, degrees, folds, self.seed)
        scores = []
        for name in names:
            template = make_model(name, self.loss)
            errors = nested.get(template.degree) if isinstance(template, Polynomial) else None
            if errors is None:
                errors = cross_validate(template, V, A, folds, self.seed)["errors_deg"]
            squared = np.sum(errors**2, axis=1) / 2.0
            scores.append(
                {
                    "model": name,
                    "n_terms": len(template.terms),
                    "cv_rms_deg": np.sqrt(np.mean(errors**2, axis=0)),
                    "mse": float(squared.mean()),
                    "mse_se": float(squared.std(ddof=1) / np.sqrt(len(squared))),
                }
            )
        if not scores:
            raise InputError(
                f"auto: {len(V)} samples are too few for any candidate form "
                f"(at least {SAMPLES_PER_TERM} per coefficient in each of {folds} folds)"
            )
        best = min(scores, key=lambda s: s["mse"])
        within = [s for s in scores if s["mse"] <= best["mse"] + best["mse_se"]]
        chosen = min(within, key=lambda s: (s["n_terms"], s["mse"]))
        self.scores_ = scores
        self.selected_ = make_model(chosen["model"], self.loss).fit(V, A)
        self.n_samples_ = len(V)
        return self

    def predict(self, voltages):
        """Pitch and roll from voltages with the chosen form (see ``Polynomial.predict``)."""
        self._check_fitted()
        return self.selected_.predict(voltages)


def _powers(u, degree):
    """u**0 … u**degree by repeated multiplication, shape (degree + 1,) + u.shape."""
    return np.cumprod([np.ones_like(u), *[u] * degree], axis=0)


def polynomial_cv_errors(voltages, angles, degrees, folds=5, seed=0):
    """Held-out errors of least-squares polynomials of several degrees, from one QR per fold.

    The folds are :func:`~reflector_opt.calibration._validation.cross_validate`'s (the same
    shuffle), each fold's inputs normalised as
    :class:`~reflector_opt.calibration._models.Polynomial` normalises its training samples;
    the fits of every degree come from one QR factorisation of the highest degree's training
    matrix (module notes).

    Parameters
    ----------
    voltages, angles : numpy.ndarray
        Shape (n_samples, 2) each: V; pitch, roll in degrees (checked).
    degrees : sequence of int
        Total degrees of the polynomials.
    folds : int
    seed : int
        Seed of the shuffle.

    Returns
    -------
    dict
        Degree → held-out errors (estimate − reference), shape (n_samples, 2), degrees. A
        degree whose training matrix is rank-deficient in some fold, or that has more terms
        than a fold has training samples, is left out (cross-validate it on its own).
    """
    if not degrees:
        return {}
    V, A = voltages, angles
    top = max(degrees)
    terms = Polynomial(top).terms  # ordered by total degree: each degree's terms lead
    sizes = {d: (d + 1) * (d + 2) // 2 for d in set(degrees)}
    centred = Polynomial(top).centred
    order = np.random.default_rng(seed).permutation(len(V))
    predicted = {d: np.empty_like(A) for d in sizes}
    for held_out in np.array_split(order, int(folds)):
        train = np.setdiff1d(order, held_out)
        centre, scale = input_normalisation(V[train], centred)

        def matrix(rows, centre=centre, scale=scale):
            u = (V[rows] - centre) / scale
            p1, p2 = _powers(u[:, 0], top), _powers(u[:, 1], top)
            return np.stack([p1[a] * p2[b] for a, b in terms], axis=-1)

        X = matrix(train)
        q, r = np.linalg.qr(X)
        qty = q.T @ A[train]
        held = matrix(held_out)
        for d, p in list(sizes.items()):
            singular = np.linalg.svd(r[:p, :p], compute_uv=False) if p <= len(train) else [0.0]
            if np.sum(singular > RANK_RTOL * singular[0]) < p:
                del sizes[d], predicted[d]  # rank-deficient: left to the ordinary path
                continue
            coef = solve_triangular(r[:p, :p], qty[:p])
            predicted[d][held_out] = held[:, :p] @ coef
    return {d: predicted[d] - A for d in sizes}
