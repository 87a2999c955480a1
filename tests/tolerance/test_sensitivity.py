"""Sobol indices against analytic ones, their intervals and flags, the pick-and-freeze rows,
and the summary of the study's groups."""

import numpy as np
import pytest

from reflector_opt.tolerance import Tolerances, draw_sample, sobol_indices
from reflector_opt.tolerance._config import parse_tolerance_config
from reflector_opt.tolerance._sensitivity import (
    NOISE,
    check_rows,
    mix,
    outside_unit_interval,
    sobol_summary,
)
from reflector_opt.util._errors import InputError


def _ishigami(x, a=7.0, b=0.1):
    return np.sin(x[:, 0]) + a * np.sin(x[:, 1]) ** 2 + b * x[:, 2] ** 4 * np.sin(x[:, 0])


def _pick_and_freeze(f, n, d, seed):
    """Outputs of f on A, B (uniform on [−π, π]^d) and every AB_i."""
    rng = np.random.default_rng(seed)
    A, B = rng.uniform(-np.pi, np.pi, (2, n, d))
    y_ab = []
    for i in range(d):
        ab = A.copy()
        ab[:, i] = B[:, i]
        y_ab.append(f(ab))
    return f(A), f(B), np.array(y_ab)


def _within(value, interval):
    return interval[0] <= value <= interval[1]


def test_sobol_indices_of_the_ishigami_function():
    """Analytic indices (a = 7, b = 0.1; Sobol' & Levitan 1999): V = a²/8 + bπ⁴/5 + b²π⁸/18 + ½,
    S1 = (½(1 + bπ⁴/5)²)/V, S2 = (a²/8)/V, S3 = 0, ST3 = (8b²π⁸/225)/V. Each lies inside
    its 99 % interval, every interval reaches into [0, 1], and none is flagged."""
    a, b = 7.0, 0.1
    v = a**2 / 8 + b * np.pi**4 / 5 + b**2 * np.pi**8 / 18 + 0.5
    v1, v2, v13 = 0.5 * (1 + b * np.pi**4 / 5) ** 2, a**2 / 8, 8 * b**2 * np.pi**8 / 225
    first = [v1 / v, v2 / v, 0.0]
    total = [(v1 + v13) / v, v2 / v, v13 / v]
    est = sobol_indices(*_pick_and_freeze(_ishigami, 4096, 3, seed=2), confidence=0.99)
    assert (est["rows"], est["dropped"], est["unused"], est["warnings"]) == (4096, 0, 0, [])
    assert est["variance"] == pytest.approx(v, rel=0.05)
    for key, exact in (("first", first), ("total", total)):
        for i in range(3):
            ci = est[f"{key}_ci"][i]
            assert ci[0] <= est[key][i] <= ci[1]
            assert _within(exact[i], ci), (key, i, exact[i], ci)
            assert ci[0] <= 1 and ci[1] >= 0 and not outside_unit_interval(ci)
            assert ci[1] - ci[0] < 0.12  # 4096 rows pin every index down to about ±0.05
    # the ranking the intervals support: x2 and x1 before x3 in first order; x1 first in total
    assert est["first_ci"][2][1] < min(est["first_ci"][0][0], est["first_ci"][1][0])
    assert est["total_ci"][0][0] > est["total_ci"][1][1] > est["total_ci"][2][1]


def test_sobol_indices_of_a_linear_model_with_an_idle_group():
    """y = 3 x1 + 2 x2 + x3 + 0 · x4 (independent, equal spreads): S_i = ST_i = a_i² / Σ a_j²
    = 9/14, 4/14, 1/14, and exactly 0 for x4 (its AB rows equal A's). Over 20 independent
    samples the 95 % intervals cover the analytic values at about their nominal rate (any one
    of them misses one time in twenty, so a single draw cannot show it)."""
    coefficients = np.array([3.0, 2.0, 1.0, 0.0])
    exact = coefficients**2 / np.sum(coefficients**2)
    covered, checks = 0, 0
    for draw in range(20):
        outputs = _pick_and_freeze(lambda x: x @ coefficients, 256, 4, seed=100 + draw)
        est = sobol_indices(*outputs, n_resamples=499, seed=draw)
        for key in ("first", "total"):
            ci = est[f"{key}_ci"]
            covered += sum(_within(exact[i], ci[i]) for i in range(3))
            checks += 3
            assert est[key][3] == 0.0 and list(ci[3]) == [0.0, 0.0]
            assert np.all(ci[:3, 0] <= 1) and np.all(ci[:3, 1] >= 0)  # reach into [0, 1]
    assert covered / checks >= 0.85, covered / checks
    # one group alone (scipy's squeezed result) carries all the variance
    alone = sobol_indices(outputs[0], outputs[1], outputs[1][None, :])
    assert _within(1.0, alone["total_ci"][0]) and _within(1.0, alone["first_ci"][0])


def test_sobol_rows_failed_units_and_the_seed():
    y_a, y_b, y_ab = _pick_and_freeze(_ishigami, 64, 3, seed=1)
    y_a[[3, 10]] = np.nan  # two units that could not be built
    y_ab[1, 20] = np.inf
    state = np.random.get_state()  # noqa: NPY002 (the global state must be left as it was)
    est = sobol_indices(y_a, y_b, y_ab, seed=4)
    assert np.array_equal(np.random.get_state()[1], state[1])  # noqa: NPY002
    assert (est["rows"], est["dropped"], est["unused"]) == (32, 3, 29)
    again = sobol_indices(y_a, y_b, y_ab, seed=4)
    other = sobol_indices(y_a, y_b, y_ab, seed=5)
    assert np.array_equal(est["total_ci"], again["total_ci"])
    assert np.array_equal(est["total"], other["total"])  # the estimate has no randomness
    assert not np.array_equal(est["total_ci"], other["total_ci"])
    with pytest.raises(InputError, match="fewer than two rows"):
        sobol_indices(np.full(4, np.nan), y_b[:4], y_ab[:, :4])
    with pytest.raises(InputError, match="shape"):
        sobol_indices(y_a, y_b, y_ab[:, :10])
    flat = sobol_indices(np.ones(8), np.ones(8), np.ones((2, 8)))  # no variance: undefined
    assert np.isnan(flat["total"]).all() and np.isnan(flat["first_ci"]).all()


def test_an_index_outside_the_unit_interval_is_flagged_only_beyond_its_interval():
    assert not outside_unit_interval((0.9, 1.3))  # 1.11 with this interval: scatter
    assert not outside_unit_interval((-0.004, -0.001))  # within the slack of 0
    assert outside_unit_interval((1.05, 1.2)) and outside_unit_interval((-0.2, -0.05))
    assert not outside_unit_interval((np.nan, np.nan))
    summary = sobol_summary(["x1", "x2"], *_fake_outputs())
    assert summary["outside"] == [
        {
            "tolerance": "x1",
            "index": "total",
            "value": summary["groups"][0]["total"],
            "ci": summary["groups"][0]["total_ci"],
        }
    ]


def _fake_outputs():
    """Outputs from a broken model run: AB_1 is A's output plus an unrelated constant-variance
    term, so its 'total index' is far above 1."""
    rng = np.random.default_rng(0)
    y_a, y_b = rng.normal(size=(2, 256))
    return y_a, y_b, np.array([y_a + 3.0 * rng.normal(size=256), y_a])


@pytest.mark.parametrize("rows", [1, 3, 100])
def test_sobol_rows_must_be_a_power_of_two(rows):
    with pytest.raises(InputError, match="power of two"):
        check_rows(rows)
    with pytest.raises(InputError, match=r"run\.sobol_samples: must be 0 \(off\) or a power"):
        parse_tolerance_config({"run": {"sobol_samples": rows}})
    assert [check_rows(n) for n in (0, 2, 256)] == [0, 2, 256]


def test_mix_takes_one_group_from_b():
    a, b = (draw_sample(Tolerances(), 2, 0, i) for i in (0, 1))
    row = mix(a, b, "gain", 9)
    assert row.index == 9 and row.noise_seed == a.noise_seed
    assert np.array_equal(row.standard["gain"], b.standard["gain"])
    assert np.array_equal(row.standard["offset_v"], a.standard["offset_v"])
    assert mix(a, b, NOISE, 9).noise_seed == b.noise_seed
    with pytest.raises(InputError, match="unknown tolerance"):
        mix(a, b, "colour", 9)
