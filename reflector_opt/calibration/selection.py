"""Choose a calibration model's form and order by cross-validation.

:class:`AutoModel` (``--model auto``) cross-validates every candidate form the data can fit
(:data:`CANDIDATES`: the paper's Eq 5 and Eq 6 and full polynomials of degree 1 to 8) and
keeps the **simplest within one standard error of the best** (the one-standard-error rule;
Hastie, Tibshirani and Friedman, *The Elements of Statistical Learning*, 2nd ed., §7.10):
the score of a form is its held-out mean squared error over both angles, its standard error
that of a mean of the pooled per-sample squared errors, and "simplest" means the fewest
coefficients per angle. The chosen form is then fitted to all the samples.
"""

from __future__ import annotations

import numpy as np

from reflector_opt.calibration.models import check_sample_pairs, make_model
from reflector_opt.calibration.validation import check_folds, cross_validate
from reflector_opt.util.errors import InputError

__all__ = ["CANDIDATES", "AutoModel"]

#: Forms :class:`AutoModel` chooses from.
CANDIDATES = ("eq5", "eq6", *(f"poly{d}" for d in range(1, 9)))

#: A form is a candidate only with at least this many samples per coefficient in every fold's
#: training set (fewer make the held-out error a poor guide).
SAMPLES_PER_TERM = 2


class AutoModel:
    """The calibration form and order chosen by k-fold cross-validation.

    Parameters
    ----------
    fit : {"lsq", "huber", "minimax"}
        The fit of every candidate.
    folds : int
        Cross-validation folds, at least 2.
    seed : int
        Seed of the fold shuffle.
    candidates : sequence of str, optional
        Form names (:func:`~reflector_opt.calibration.models.make_model`); default
        :data:`CANDIDATES`.

    Attributes
    ----------
    selected_ : Eq5, Eq6 or Polynomial
        The chosen form, fitted to every sample (after :meth:`fit`).
    scores_ : list of dict
        Per candidate tried: ``model``, ``n_terms``, ``cv_rms_deg`` (pitch, roll), ``mse``
        and ``mse_se`` (deg², both angles pooled).
    """

    name = "auto"

    def __init__(self, *, fit="lsq", folds=5, seed=0, candidates=None):
        self.fit_method = fit
        self.folds = folds
        self.seed = seed
        self.candidates = candidates

    def get_params(self):
        """Constructor parameters (scikit-learn style)."""
        return {
            "fit": self.fit_method,
            "folds": self.folds,
            "seed": self.seed,
            "candidates": self.candidates,
        }

    def clone(self):
        """An unfitted copy with the same parameters."""
        return type(self)(**self.get_params())

    def __repr__(self):
        params = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"AutoModel({params})"

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
        scores = []
        for name in self.candidates or CANDIDATES:
            template = make_model(name, self.fit_method)
            if training < SAMPLES_PER_TERM * len(template.terms):
                continue
            cv = cross_validate(template, V, A, folds, self.seed)
            squared = np.sum(cv["errors_deg"] ** 2, axis=1) / 2.0
            scores.append(
                {
                    "model": name,
                    "n_terms": len(template.terms),
                    "cv_rms_deg": cv["rms_deg"],
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
        self.selected_ = make_model(chosen["model"], self.fit_method).fit(V, A)
        return self

    def predict(self, voltages):
        """Pitch and roll from voltages with the chosen form (see ``Polynomial.predict``)."""
        if not hasattr(self, "selected_"):
            raise InputError("AutoModel is not fitted; call fit() first")
        return self.selected_.predict(voltages)
