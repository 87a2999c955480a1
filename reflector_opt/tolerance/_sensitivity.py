"""Variance-based (Sobol) sensitivity indices of groups of inputs, with confidence intervals.

The pick-and-freeze design of Saltelli et al. (2010): two independent sample matrices A and B
of N rows, and for each group i the matrix AB_i, equal to A except in the columns of group i,
which come from B. The study evaluates the model on every row of them on its executor
(:mod:`reflector_opt.tolerance._study`); the indices are then computed by
:func:`scipy.stats.sobol_indices` from those outputs (its ``func`` given as the precomputed
``f_A``, ``f_B``, ``f_AB``). With y the model output and V the variance over A and B together,
scipy's default estimators are

* first-order index (Saltelli et al. 2010, Table 2 (b)):
  ``S_i = mean(y_B · (y_ABi − y_A)) / V``
* total index (Jansen 1999; Saltelli et al. 2010, Table 2 (f)):
  ``ST_i = mean((y_A − y_ABi)²) / (2 V)``

and the confidence intervals are BCa bootstrap intervals over the rows
(``SobolResult.bootstrap``, i.e. :func:`scipy.stats.bootstrap`). A group may hold several
inputs (all components of a tolerance); the indices are then those of the group as one input.
Cost: N (k + 2) model runs for k groups. :func:`sobol_summary` gives the indices of the study's
groups, their intervals and the flagged ones as a JSON-ready record.

Nothing is clipped. Both indices lie in [0, 1] in theory, but the estimates scatter around the
true values; an estimate outside [0, 1] whose interval still reaches into [0, 1] is sampling
scatter, while one whose whole interval lies outside (by more than :data:`SLACK`) is flagged
(:func:`outside_unit_interval`): it points to a fault in the model runs or the design, not to
chance.

References: A. Saltelli et al., "Variance based sensitivity analysis of model output. Design
and estimator for the total sensitivity index", Comput. Phys. Commun. 181 (2010) 259–270;
M. J. W. Jansen, "Analysis of variance designs for model output", Comput. Phys. Commun. 117
(1999) 35–43.
"""

import warnings
from contextlib import contextmanager

import numpy as np

from reflector_opt.tolerance._tolerances import Draw
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import json_number

#: Name of the group that holds the calibration's random draws (poses, noise, ADC).
NOISE = "noise"

#: Confidence level of the intervals.
CONFIDENCE = 0.95

#: Bootstrap resamples of the rows.
RESAMPLES = 999

#: How far outside [0, 1] a whole interval must lie to be flagged
#: (:func:`outside_unit_interval`): 1 % of the output variance.
SLACK = 0.01


def check_rows(n, where="sobol samples"):
    """``n`` if it is 0 (no Sobol analysis) or a power of two ≥ 2, else an InputError.

    :func:`scipy.stats.sobol_indices` takes only a power of two of rows.
    """
    if isinstance(n, bool) or not isinstance(n, int) or n < 0:
        raise InputError(f"{where}: must be a whole number ≥ 0, got {n!r}")
    if n == 1 or n & (n - 1):
        raise InputError(
            f"{where}: must be 0 (off) or a power of two ≥ 2 (2, 4, … 256, 512; the Sobol "
            f"estimator of scipy requires it), got {n}"
        )
    return n


@contextmanager
def _global_random_state(seed):
    """NumPy's global random state seeded from ``seed`` inside the block, restored after.

    ``SobolResult.bootstrap`` takes no generator (scipy ≤ 1.17): it resamples with NumPy's
    global ``RandomState``. Seeding it here makes the intervals a function of the seed.
    """
    saved = np.random.get_state()  # noqa: NPY002 (scipy draws from the global state)
    np.random.seed(int(np.random.SeedSequence(int(seed)).generate_state(1)[0]))  # noqa: NPY002
    try:
        yield
    finally:
        np.random.set_state(saved)  # noqa: NPY002


def sobol_indices(y_a, y_b, y_ab, *, confidence=CONFIDENCE, n_resamples=RESAMPLES, seed=0):
    """First-order and total Sobol indices with bootstrap intervals, by scipy.

    Parameters
    ----------
    y_a, y_b : array_like
        Shape (N,): outputs on the rows of A and of B (any unit; the indices have none).
    y_ab : array_like
        Shape (k, N): outputs on AB_i, i = 1…k.
    confidence : float
        Confidence level of the intervals, strictly between 0 and 1.
    n_resamples : int
        Bootstrap resamples of the rows (≥ 1).
    seed : int
        Seed of the resampling (≥ 0).

    Returns
    -------
    dict
        ``first``, ``total`` (shape (k,)); ``first_ci``, ``total_ci`` (shape (k, 2): low,
        high); ``variance`` (of the output over A and B, its unit squared); ``rows`` (rows
        used); ``dropped`` (rows left out because an output in them is not finite: a unit that
        could not be built or calibrated); ``unused`` (finite rows left out to keep a power of
        two, the last ones); ``warnings`` (messages of a degenerate bootstrap, whose NaN bounds
        mean "undefined"). A group that changes the output on no row has indices 0 with
        interval [0, 0]; with zero variance every index and bound is NaN (undefined). Values
        are never clipped to [0, 1]; see :func:`outside_unit_interval`.

    Raises
    ------
    InputError
        On mismatched shapes, or fewer than two rows with finite outputs.
    """
    y_a, y_b, y_ab = (np.asarray(y, dtype=float) for y in (y_a, y_b, y_ab))
    if y_a.ndim != 1 or y_b.shape != y_a.shape or y_ab.ndim != 2 or y_ab.shape[1] != y_a.size:
        raise InputError("sobol_indices: expected y_a, y_b of shape (N,) and y_ab of shape (k, N)")
    if not 0.0 < confidence < 1.0:
        raise InputError(f"sobol_indices: confidence must lie in (0, 1), got {confidence!r}")
    keep = np.flatnonzero(np.isfinite(y_a) & np.isfinite(y_b) & np.all(np.isfinite(y_ab), axis=0))
    if keep.size < 2:
        raise InputError("sobol_indices: fewer than two rows with finite outputs")
    rows = 1 << (keep.size.bit_length() - 1)  # the largest power of two ≤ the finite rows
    used = keep[:rows]
    k = y_ab.shape[0]
    out = {
        "rows": int(rows),
        "dropped": int(y_a.size - keep.size),
        "unused": int(keep.size - rows),
        "variance": float(np.var(np.concatenate([y_a[used], y_b[used]]))),
    }
    out |= {
        "first": np.zeros(k),
        "total": np.zeros(k),
        "first_ci": np.zeros((k, 2)),
        "total_ci": np.zeros((k, 2)),
        "warnings": [],
    }
    if out["variance"] == 0.0:
        for key in ("first", "total", "first_ci", "total_ci"):
            out[key][...] = np.nan
        return out
    # A group whose every AB row gives the A row's output changes nothing: both estimates are
    # exactly 0 in every resample, for which a BCa interval is undefined (0/0); it is [0, 0].
    moves = np.flatnonzero(np.any(y_ab[:, used] != y_a[used], axis=1))
    if moves.size:
        found = _scipy_indices(
            y_a[used], y_b[used], y_ab[moves][:, used], confidence, n_resamples, seed
        )
        for key, values in found.items():
            if key == "warnings":
                out[key] = values
            else:
                out[key][moves] = values
    return out


def _scipy_indices(y_a, y_b, y_ab, confidence, n_resamples, seed):
    """:func:`scipy.stats.sobol_indices` and its bootstrap on rows of finite outputs."""
    import scipy.stats  # costs about a second to import: only when indices are computed

    k, rows = y_ab.shape
    # scipy's layout: f_A, f_B (outputs s, rows n) and f_AB (groups d, s, n). scipy squeezes its
    # (s, d) result, which for s = d = 1 leaves a scalar it cannot index (scipy ≤ 1.17); a
    # single group therefore goes in as two identical outputs, of which the first is read.
    s = 2 if k == 1 else 1
    f_a = np.tile(y_a, (s, 1))
    f_b = np.tile(y_b, (s, 1))
    f_ab = np.tile(y_ab[:, None, :], (1, s, 1))
    result = scipy.stats.sobol_indices(func={"f_A": f_a, "f_B": f_b, "f_AB": f_ab}, n=rows)
    # A degenerate bootstrap (e.g. a handful of rows) warns and gives NaN bounds: the warning is
    # returned with the result, the NaN bounds reported as undefined.
    with _global_random_state(seed), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        boot = result.bootstrap(confidence_level=confidence, n_resamples=int(n_resamples))

    def per_group(values):
        values = np.asarray(values, dtype=float)
        return values.reshape(s, k)[0] if s == 2 else values.reshape(k)

    out = {"warnings": sorted({str(w.message) for w in caught})}
    for key, point, interval in (
        ("first", result.first_order, boot.first_order.confidence_interval),
        ("total", result.total_order, boot.total_order.confidence_interval),
    ):
        out[key] = per_group(point)
        out[f"{key}_ci"] = np.column_stack([per_group(interval.low), per_group(interval.high)])
    return out


def outside_unit_interval(interval, slack=SLACK):
    """Whether an index lies outside [0, 1] beyond its confidence interval (and ``slack``).

    An interval that still reaches into [0, 1] is sampling scatter. One that misses it by more
    than ``slack`` is not: the model runs or the sample design are at fault. The slack keeps
    indices of groups with almost no effect from raising the alarm: their intervals are so
    narrow (the AB outputs hardly differ from A) that the estimator's own small bias, of the
    order of 10⁻³, can put a whole interval just below 0.

    Parameters
    ----------
    interval : sequence of float
        (low, high) of the index.
    slack : float
        How far outside [0, 1] the whole interval must lie.

    Returns
    -------
    bool
        False for NaN bounds.
    """
    low, high = interval
    return bool(high < -slack or low > 1.0 + slack)


def mix(draw_a, draw_b, group, index):
    """The AB row: ``draw_a`` with ``group`` (a tolerance name or :data:`NOISE`) from ``draw_b``.

    Parameters
    ----------
    draw_a, draw_b : reflector_opt.tolerance._tolerances.Draw
    group : str
    index : int
        Index of the new row (results are keyed by it).

    Returns
    -------
    reflector_opt.tolerance._tolerances.Draw
    """
    if group == NOISE:
        return Draw(index, draw_a.standard, draw_b.noise_seed)
    if group not in draw_a.standard:
        raise InputError(f"unknown tolerance {group!r}")
    return Draw(index, {**draw_a.standard, group: draw_b.standard[group]}, draw_a.noise_seed)


def sobol_summary(groups, y_a, y_b, y_ab, seed=0):
    """JSON-ready Sobol indices of the sensitivity output per group, with their intervals.

    Parameters
    ----------
    groups : sequence of str
        Tolerance names (and :data:`~reflector_opt.tolerance._sensitivity.NOISE`), in the
        order of ``y_ab``.
    y_a, y_b : array_like
        Shape (N,): the output on the rows of A and B, degrees (NaN: a failed unit).
    y_ab : array_like
        Shape (k, N): on the rows of AB_i.
    seed : int
        Seed of the bootstrap.

    Returns
    -------
    dict
        ``method``, ``confidence``, ``resamples``; ``rows_requested`` (N), ``rows`` (used),
        ``dropped`` (rows with a failed unit), ``unused`` (left out to keep a power of two);
        ``variance_deg2``; ``groups``: per group ``tolerance``, ``first``, ``first_ci``,
        ``total``, ``total_ci`` (None where undefined: zero variance, degenerate bootstrap);
        ``outside``: the indices whose whole interval lies outside [0, 1] by more than
        ``slack`` (:func:`~reflector_opt.tolerance._sensitivity.outside_unit_interval`;
        ``tolerance``, ``index`` "first" or "total", ``value``, ``ci``), which sampling
        scatter does not explain — empty unless something is wrong; ``warnings`` of the
        bootstrap. Nothing is clipped. Fewer than two rows without a failed
        unit give None indices and an ``error``.
    """
    n = len(y_a)
    out = {
        "method": "scipy.stats.sobol_indices: first-order Saltelli (2010), total Jansen "
        "(1999); BCa bootstrap intervals over the rows",
        "confidence": CONFIDENCE,
        "resamples": RESAMPLES,
        "slack": SLACK,
        "rows_requested": n,
    }
    try:
        est = sobol_indices(y_a, y_b, y_ab, confidence=CONFIDENCE, n_resamples=RESAMPLES, seed=seed)
    except InputError as exc:  # fewer than two rows without a failed unit
        return out | _no_indices(groups, y_a, y_b, y_ab, exc)
    out |= {
        "rows": est["rows"],
        "dropped": est["dropped"],
        "unused": est["unused"],
        "variance_deg2": json_number(est["variance"]),
    }
    rows, outside = [], []
    for i, group in enumerate(groups):
        row = {"tolerance": group}
        for key in ("first", "total"):
            value = json_number(float(est[key][i]))
            ci = [json_number(float(v)) for v in est[f"{key}_ci"][i]]
            row[key], row[f"{key}_ci"] = value, ci
            if None not in ci and outside_unit_interval(ci):
                outside.append({"tolerance": group, "index": key, "value": value, "ci": ci})
        rows.append(row)
    return out | {"groups": rows, "outside": outside, "warnings": est["warnings"]}


def _no_indices(groups, y_a, y_b, y_ab, error):
    """The entries of :func:`sobol_summary` when too few rows leave indices undefined."""
    finite = int(np.isfinite(np.vstack([y_a, y_b, y_ab])).all(axis=0).sum())
    empty = {"first": None, "first_ci": [None, None], "total": None, "total_ci": [None, None]}
    return {
        "rows": 0,
        "dropped": len(y_a) - finite,
        "unused": finite,
        "variance_deg2": None,
        "error": str(error),
        "outside": [],
        "warnings": [],
        "groups": [{"tolerance": g, **empty} for g in groups],
    }
