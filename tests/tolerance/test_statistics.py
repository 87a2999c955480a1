"""The statistics of a tolerance study's sample: yield and its Wilson interval, the required
margin and its order-statistic bound, by hand and by Monte Carlo."""

import math

import numpy as np
import pytest
from scipy.stats import norm

from reflector_opt.tolerance import Targets
from reflector_opt.tolerance._statistics import quantile_upper_bound, summarise, yield_interval


def _record(status, window, margin, rms, worst):
    nan = math.nan
    return {
        "status": status,
        "window_kept": window,
        "distance_margin_mm": margin if status == "ok" else nan,
        "resolution_pitch_deg": 0.1,
        "resolution_roll_deg": 0.1,
        "wall_min_mm": 1.0,
        "rms_pitch_deg": rms,
        "rms_roll_deg": rms / 2,
        "max_pitch_deg": worst,
        "max_roll_deg": worst / 2,
    }


def test_summary_yield_and_required_margin_hand_values():
    records = [
        _record("ok", True, 0.20, 0.5, 2.0),  # passes
        _record("ok", True, 0.10, 1.5, 2.0),  # RMS too large
        _record("ok", False, -0.05, 0.5, 4.0),  # window lost, maximum too large
        _record("invalid", False, math.nan, math.nan, math.nan),
    ]
    s = summarise(records, Targets(rms_deg=1.0, max_deg=3.0), coverage=1.0, nominal_margin_mm=0.3)
    assert s["yield"] == {"all": 0.25, "window": 0.5, "rms": 0.5, "max": 0.5}
    assert (s["samples"], s["invalid"], s["unfit"]) == (4, 1, 0)
    assert s["required_margin_mm"]["value"] == pytest.approx(0.35)  # 0.3 − (−0.05)
    assert s["distributions"]["distance_margin_mm"]["max"] == pytest.approx(0.2)


def test_required_margin_is_a_confidence_bound_with_enough_units():
    """300 units ≥ 299: the 95 % bound on the 99 % quantile of the loss is the largest loss."""
    losses = np.linspace(0.0, 0.299, 300)
    records = [_record("ok", True, 0.3 - loss, 0.5, 2.0) for loss in losses]
    s = summarise(records, Targets(rms_deg=1.0, max_deg=3.0), nominal_margin_mm=0.3)
    required = s["required_margin_mm"]
    assert required["confidence"] == 0.95
    assert required["value"] == pytest.approx(0.299)
    assert required["estimate"] == pytest.approx(np.quantile(losses, 0.99))


def _wilson(k, n, confidence=0.95):
    """Wilson (1927) score interval, written out."""
    z = norm.ppf(0.5 + confidence / 2)
    p = k / n
    centre = (p + z**2 / (2 * n)) / (1 + z**2 / n)
    half = z / (1 + z**2 / n) * math.sqrt(p * (1 - p) / n + z**2 / (4 * n**2))
    return centre - half, centre + half


def test_quantile_upper_bound_by_hand():
    """0.99²⁹⁹ = 0.0495 < 5 %: with 299 samples the maximum bounds the 99 % quantile at 95 %;
    0.99²⁹⁸ = 0.0500 > 5 %: 298 samples cannot."""
    assert quantile_upper_bound(np.arange(299.0), 0.99) == 298.0
    assert quantile_upper_bound(np.arange(298.0), 0.99) is None
    # median at 95 %: the smallest k with P(Bin(20, 1/2) ≤ k − 1) ≥ 0.95 is k = 15
    assert quantile_upper_bound(np.arange(1.0, 21.0), 0.5) == 15.0


def test_quantile_upper_bound_covers_the_true_quantile_95_percent_of_the_time():
    """Monte Carlo: 4,000 sets of 500 normal samples. The bound is the 499th of 500, above
    the true 99 % quantile with probability P(Bin(500, 0.99) ≤ 498) = 96.02 % (≥ 95 %, the
    excess from k being whole); the fraction of sets has σ 0.31 %."""
    rng = np.random.default_rng(3)
    true_quantile = norm.ppf(0.99)
    covered = [
        quantile_upper_bound(rng.standard_normal(500), 0.99) >= true_quantile for _ in range(4000)
    ]
    assert np.mean(covered) == pytest.approx(0.9602, abs=0.0125)  # 4 σ


@pytest.mark.parametrize(("passed", "samples"), [(45, 50), (20, 20), (0, 7), (1, 3)])
def test_yield_interval_is_wilsons_and_contains_the_estimate(passed, samples):
    low, high = yield_interval(passed, samples)
    assert (low, high) == pytest.approx(_wilson(passed, samples), abs=1e-12)
    assert 0.0 <= low <= passed / samples <= high <= 1.0
    assert low < high


def test_yield_interval_by_hand():
    # 45 of 50, z = 1.959964, z² = 3.841459: centre (0.9 + 0.038415) / 1.076829 = 0.871461,
    # half (1.959964 / 1.076829) · sqrt(0.0018 + 0.000384146) = 1.820125 · 0.046735 = 0.085063
    assert yield_interval(45, 50) == pytest.approx((0.786398, 0.956524), abs=2e-6)
    # all of 20 pass: the interval still has width, [20 / (20 + z²), 1]
    assert yield_interval(20, 20) == pytest.approx((20 / (20 + 1.959964**2), 1.0), abs=1e-6)
