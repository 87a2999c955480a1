"""The statistics of a tolerance study's sample: the yield with its Wilson interval, the
distribution of every output, and the distance-window margin that a chosen fraction of built
units keeps, with its distribution-free upper confidence bound.
"""

import numpy as np

from reflector_opt.tolerance._analysis import ASSESSED, METRIC_COLUMNS, passes
from reflector_opt.util._errors import InputError

#: Default fraction of built units the required margin covers.
COVERAGE = 0.99

#: Confidence level of the yield intervals.
CONFIDENCE = 0.95


def check_coverage(coverage):
    """``coverage`` as a float, if it is a fraction strictly between 0 and 1."""
    if isinstance(coverage, bool) or not isinstance(coverage, int | float):
        raise InputError(f"coverage: expected a fraction between 0 and 1, got {coverage!r}")
    if not 0.0 < coverage < 1.0:
        raise InputError(f"coverage: must be strictly between 0 and 1, got {coverage!r}")
    return float(coverage)


def yield_interval(passed, samples, confidence=CONFIDENCE):
    """Wilson score interval of a yield estimated from ``passed`` of ``samples`` units.

    With p̂ = k/n and z the two-sided normal quantile of ``confidence``,

        (p̂ + z²/2n ± z·sqrt(p̂(1 − p̂)/n + z²/4n²)) / (1 + z²/n)

    (Wilson 1927; computed by :meth:`scipy.stats.binomtest`'s ``proportion_ci``). Unlike the
    normal approximation it stays inside [0, 1] and does not collapse to a point when every
    unit (or none) passes.

    Parameters
    ----------
    passed : int
        Units that met the targets.
    samples : int
        Units sampled (≥ 1).
    confidence : float
        Confidence level, strictly between 0 and 1.

    Returns
    -------
    tuple of float
        (low, high), fractions.
    """
    from scipy.stats import binomtest  # scipy.stats costs about a second to import

    ci = binomtest(int(passed), int(samples)).proportion_ci(
        confidence_level=confidence, method="wilson"
    )
    return float(ci.low), float(ci.high)


def quantile_upper_bound(values, coverage, confidence=CONFIDENCE):
    """Distribution-free upper confidence bound of the ``coverage`` quantile of ``values``.

    Of n independent samples sorted as X(1) ≤ … ≤ X(n), the number below the true quantile
    q_c is binomial (n, c), so ``P(X(k) ≥ q_c) = P(Bin(n, c) ≤ k − 1)``; the bound is X(k) for
    the smallest k with that probability ≥ ``confidence`` (the order-statistic bound of
    e.g. Hahn & Meeker, *Statistical Intervals*, 1991, ch. 5). It holds for any continuous
    distribution. Too few samples for it (cⁿ > 1 − confidence, e.g. n < 299 for a 99 %
    quantile at 95 %) give None.

    Parameters
    ----------
    values : array_like
        The samples.
    coverage : float
        The quantile, strictly between 0 and 1.
    confidence : float
        Confidence level, strictly between 0 and 1.

    Returns
    -------
    float or None
    """
    from scipy.stats import binom  # scipy.stats costs about a second to import

    ordered = np.sort(np.asarray(values, dtype=float))
    k = int(binom.ppf(confidence, ordered.size, coverage)) + 1
    return float(ordered[k - 1]) if k <= ordered.size else None


def _percentiles(values):
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if not values.size:
        return None
    p5, p50, p95 = np.percentile(values, [5, 50, 95])
    return {
        "mean": float(values.mean()),
        "p5": float(p5),
        "median": float(p50),
        "p95": float(p95),
        "max": float(values.max()),
    }


def summarise(records, targets, coverage=COVERAGE, nominal_margin_mm=None):
    """Distributions, yield and the distance margin that covers the tolerances.

    Parameters
    ----------
    records : list of dict
        Results of :func:`reflector_opt.tolerance._analysis.evaluate_draw`.
    targets : Targets
    coverage : float
        Fraction of built units the required margin must cover.
    nominal_margin_mm : float, optional
        Distance-window margin of the nominal design, mm.

    Returns
    -------
    dict
        JSON-ready: ``samples``, ``invalid`` and ``unfit`` (counts of units not built or not
        calibratable), ``yield`` (overall and per target; ``rms`` and ``max`` are None for
        uncalibrated records), ``yield_interval`` (95 % Wilson intervals of the overall and
        the window yield, :func:`yield_interval`),
        ``distributions`` (mean, p5, median, p95, max of every output over the assessed
        units), and with
        ``nominal_margin_mm`` the ``required_margin_mm``: the loss of distance-window margin
        from nominal to as built that ``coverage`` of the units stay within — ``estimate``
        the sample quantile, ``value`` its 95 % upper confidence bound
        (:func:`quantile_upper_bound`; the estimate, with ``confidence`` None, when there
        are too few samples for the bound). ``value`` is the margin to give the optimiser's
        ``distance_margin_mm`` constraint so that that fraction of units keeps its window
        (for designs near this one).
    """
    n = len(records)
    ok = [r for r in records if r["status"] in ASSESSED]
    calibrated = not any(r["status"] == "uncalibrated" for r in records)
    passed = sum(passes(r, targets) for r in records)
    window = sum(bool(r["window_kept"]) for r in records)
    rms = sum(
        r["status"] == "ok" and max(r["rms_pitch_deg"], r["rms_roll_deg"]) <= targets.rms_deg
        for r in records
    )
    worst = sum(
        r["status"] == "ok" and max(r["max_pitch_deg"], r["max_roll_deg"]) <= targets.max_deg
        for r in records
    )
    out = {
        "samples": n,
        "invalid": sum(r["status"] == "invalid" for r in records),
        "unfit": sum(r["status"] == "unfit" for r in records),
        "targets": targets.to_dict(),
        "yield": {
            "all": passed / n,
            "window": window / n,
            "rms": rms / n if calibrated else None,
            "max": worst / n if calibrated else None,
        },
        "yield_interval": {
            "confidence": CONFIDENCE,
            "method": "wilson",
            "all": list(yield_interval(passed, n)),
            "window": list(yield_interval(window, n)),
        },
        "distributions": {key: _percentiles([r[key] for r in ok]) for key in METRIC_COLUMNS},
    }
    if nominal_margin_mm is not None and ok:
        out["required_margin_mm"] = _required_margin(ok, nominal_margin_mm, coverage)
    return out


def _required_margin(assessed, nominal_margin_mm, coverage):
    """The loss of window margin ``coverage`` of the assessed units stay within: the sample
    quantile and its upper confidence bound (see :func:`summarise`), mm."""
    loss = nominal_margin_mm - np.array([r["distance_margin_mm"] for r in assessed])
    estimate = max(float(np.quantile(loss, coverage)), 0.0)
    bound = quantile_upper_bound(loss, coverage)
    return {
        "coverage": coverage,
        "confidence": CONFIDENCE if bound is not None else None,
        "estimate": estimate,
        "value": max(bound, 0.0) if bound is not None else estimate,
    }
