"""Variance-based (Sobol) sensitivity indices of groups of inputs.

The pick-and-freeze design of Saltelli et al. (2010): two independent sample matrices A and B
of N rows, and for each group i the matrix AB_i, equal to A except in the columns of group i,
which come from B. With the model output y, the total variance V estimated from A and B
together:

* first-order index (Saltelli et al. 2010, Table 2 (b)):
  ``S_i = mean(y_B · (y_ABi − y_A)) / V``
* total index (Jansen 1999; Saltelli et al. 2010, Table 2 (f)):
  ``ST_i = mean((y_A − y_ABi)²) / (2 V)``

A group may hold several inputs (all components of a tolerance); the indices are then those
of the group as one input. Cost: N (k + 2) model runs for k groups.

References: A. Saltelli et al., "Variance based sensitivity analysis of model output. Design
and estimator for the total sensitivity index", Comput. Phys. Commun. 181 (2010) 259–270;
M. J. W. Jansen, "Analysis of variance designs for model output", Comput. Phys. Commun. 117
(1999) 35–43.
"""

from __future__ import annotations

import numpy as np

from reflector_opt.tolerance.model import Draw
from reflector_opt.util.errors import InputError

__all__ = ["NOISE", "mix", "sobol_indices"]

#: Name of the group that holds the calibration's random draws (poses, noise, ADC).
NOISE = "noise"


def sobol_indices(y_a, y_b, y_ab, n_bootstrap=0, rng=None):
    """First-order and total Sobol indices from a pick-and-freeze sample.

    Parameters
    ----------
    y_a, y_b : array_like
        Shape (N,): outputs on the rows of A and of B.
    y_ab : array_like
        Shape (k, N): outputs on AB_i, i = 1…k.
    n_bootstrap : int, optional
        Bootstrap resamples of the rows for 95 % confidence intervals (0: none).
    rng : numpy.random.Generator, optional
        Source of the resampling.

    Returns
    -------
    dict
        ``first``, ``total`` (shape (k,)), ``variance``, ``n``; with ``n_bootstrap`` also
        ``first_ci`` and ``total_ci`` (shape (k, 2)). Rows with a non-finite output anywhere
        are dropped first.
    """
    y_a, y_b, y_ab = (np.asarray(y, dtype=float) for y in (y_a, y_b, y_ab))
    if y_a.ndim != 1 or y_b.shape != y_a.shape or y_ab.ndim != 2 or y_ab.shape[1] != y_a.size:
        raise InputError("sobol_indices: expected y_a, y_b of shape (N,) and y_ab of shape (k, N)")
    keep = np.isfinite(y_a) & np.isfinite(y_b) & np.all(np.isfinite(y_ab), axis=0)
    y_a, y_b, y_ab = y_a[keep], y_b[keep], y_ab[:, keep]
    if y_a.size < 2:
        raise InputError("sobol_indices: fewer than two rows with finite outputs")

    def estimate(rows):
        a, b, ab = y_a[rows], y_b[rows], y_ab[:, rows]
        variance = np.var(np.concatenate([a, b]))
        if variance == 0:
            nan = np.full(ab.shape[0], np.nan)
            return nan, nan, 0.0
        first = np.mean(b * (ab - a), axis=1) / variance
        total = 0.5 * np.mean((a - ab) ** 2, axis=1) / variance
        return first, total, float(variance)

    first, total, variance = estimate(np.arange(y_a.size))
    out = {"first": first, "total": total, "variance": variance, "n": int(y_a.size)}
    if n_bootstrap:
        rng = np.random.default_rng(0) if rng is None else rng
        boot = [estimate(rng.integers(0, y_a.size, y_a.size)) for _ in range(int(n_bootstrap))]
        for key, k in (("first_ci", 0), ("total_ci", 1)):
            values = np.array([b[k] for b in boot])
            out[key] = np.nanpercentile(values, [2.5, 97.5], axis=0).T
    return out


def mix(draw_a, draw_b, group, index):
    """The AB row: ``draw_a`` with ``group`` (a tolerance name or :data:`NOISE`) from ``draw_b``.

    Parameters
    ----------
    draw_a, draw_b : reflector_opt.tolerance.model.Draw
    group : str
    index : int
        Index of the new row (results are keyed by it).

    Returns
    -------
    reflector_opt.tolerance.model.Draw
    """
    if group == NOISE:
        return Draw(index, draw_a.standard, draw_b.noise_seed)
    if group not in draw_a.standard:
        raise InputError(f"unknown tolerance {group!r}")
    return Draw(index, {**draw_a.standard, group: draw_b.standard[group]}, draw_a.noise_seed)
