"""K-fold cross-validation of a calibration model: its error on samples it was not fitted to."""

import numpy as np

from reflector_opt.calibration._models import check_sample_pairs
from reflector_opt.util._errors import InputError


def check_folds(folds):
    """``folds`` as the number of folds of a cross-validation, a whole number ≥ 2; else
    InputError."""
    if isinstance(folds, bool) or int(folds) != folds or folds < 2:
        raise InputError(f"folds: must be a whole number of at least 2, got {folds}")
    return int(folds)


def cross_validate(model, voltages, angles, folds=5, seed=0, temperature_c=None):
    """K-fold cross-validated error of a calibration model.

    Samples are shuffled (seeded) into ``folds`` groups; each group is predicted by a copy
    of ``model`` fitted on the others. The statistics pool every held-out prediction.

    Parameters
    ----------
    model : Eq5, Eq6, Polynomial or TemperatureCompensated
        Used as a template (not modified).
    voltages, angles : array_like
        Shape (n_samples, 2) each: V; pitch, roll in degrees.
    folds : int
        Number of folds, at least 2.
    seed : int
        Seed of the shuffle.
    temperature_c : array_like, optional
        Shape (n_samples,): each sample's temperature, °C, passed to a compensated model's
        ``fit`` and ``predict`` after the voltages and angles.

    Returns
    -------
    dict
        ``rms_deg`` and ``max_deg``: arrays (pitch, roll), degrees; ``folds``;
        ``errors_deg``: every held-out error (estimate − reference), shape (n_samples, 2).
    """
    V, A = check_sample_pairs(voltages, angles, "cross-validation")
    check_folds(folds)
    if folds > len(V):
        raise InputError(f"folds: {folds} folds need at least {folds} samples, got {len(V)}")
    order = np.random.default_rng(seed).permutation(len(V))
    extra = () if temperature_c is None else (np.asarray(temperature_c, dtype=float),)
    predicted = np.empty_like(A)
    for i, held_out in enumerate(np.array_split(order, int(folds))):
        train = np.setdiff1d(order, held_out)
        try:
            fitted = model.clone().fit(V[train], A[train], *(t[train] for t in extra))
        except InputError as exc:
            raise type(exc)(f"cross-validation fold {i + 1} of {folds}: {exc}") from None
        predicted[held_out] = fitted.predict(V[held_out], *(t[held_out] for t in extra))
    error = predicted - A
    return {
        "rms_deg": np.sqrt(np.mean(error**2, axis=0)),
        "max_deg": np.abs(error).max(axis=0),
        "folds": int(folds),
        "errors_deg": error,
    }
