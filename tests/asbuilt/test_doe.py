"""Bayesian D-optimal design on random information blocks: against direct determinants and
brute-force search, and the properties the algebra promises."""

import itertools

import numpy as np
import pytest

from reflector_opt.asbuilt._doe import (
    d_optimal,
    exchange,
    greedy_selection,
    information_matrix,
    minimum_poses,
    poses_needed,
    std_ratio,
)
from reflector_opt.util._errors import InputError


def _log_det(rows):
    """log det(I + Σ A_iᵀA_i) summed pose by pose, not through the module."""
    p = rows.shape[-1]
    m = np.eye(p)
    for block in rows:
        for row in block:
            m += np.outer(row, row)
    return np.linalg.slogdet(m)[1]


@pytest.fixture(scope="module")
def random_rows():
    """40 candidate poses of 2 sensors and 6 parameters, of uneven strength."""
    rng = np.random.default_rng(3)
    return rng.normal(size=(40, 2, 6)) * np.array([3.0, 1.0, 0.5, 0.2, 0.1, 0.05])


def test_information_and_ratio_by_hand():
    # one pose, two sensors, each seeing one parameter: M = diag(1 + 3², 1 + 4²)
    rows = np.array([[[3.0, 0.0], [0.0, 4.0]]])
    np.testing.assert_allclose(information_matrix(rows), [[10.0, 0.0], [0.0, 17.0]])
    np.testing.assert_allclose(
        std_ratio(information_matrix(rows)), [1 / np.sqrt(10), 1 / np.sqrt(17)]
    )
    # no pose: the prior alone
    np.testing.assert_array_equal(information_matrix(np.zeros((0, 2, 3))), np.eye(3))


def test_minimum_poses_is_one_voltage_per_parameter():
    assert minimum_poses(np.zeros((5, 2, 24))) == 12
    assert minimum_poses(np.zeros((5, 2, 25))) == 13
    assert minimum_poses(np.zeros((5, 3, 7))) == 3


def test_greedy_update_equals_the_direct_determinant(random_rows):
    order, gains, variances = greedy_selection(random_rows, 12)
    assert len(set(order.tolist())) == 12
    for k in range(1, 13):
        taken = random_rows[order[:k]]
        assert np.sum(gains[:k]) == pytest.approx(_log_det(taken), rel=1e-10, abs=1e-10)
        flat = taken.reshape(-1, 6)
        direct = np.diag(np.linalg.inv(np.eye(6) + flat.T @ flat))
        np.testing.assert_allclose(variances[k - 1], direct, rtol=1e-9)
    # each step took the candidate of largest direct determinant among those left
    for k in range(12):
        left = [i for i in range(40) if i not in order[:k]]
        direct = [_log_det(random_rows[[*order[:k], i]]) for i in left]
        assert _log_det(random_rows[order[: k + 1]]) == pytest.approx(max(direct), abs=1e-9)


def test_greedy_refuses_a_plan_larger_than_the_candidates(random_rows):
    with pytest.raises(InputError, match="plan size"):
        greedy_selection(random_rows, 41)


def test_exchange_ends_where_no_single_swap_raises_the_determinant(random_rows):
    start = np.arange(10)  # a poor start: the first ten candidates
    plan = exchange(random_rows, start)
    best = _log_det(random_rows[plan])
    assert best > _log_det(random_rows[start]) + 1.0
    assert len(set(plan.tolist())) == 10
    for k in range(10):
        for j in set(range(40)) - set(plan.tolist()):
            swapped = plan.copy()
            swapped[k] = j
            assert _log_det(random_rows[swapped]) <= best + 1e-9


@pytest.mark.parametrize("seed", range(8))
def test_exchange_never_lowers_the_determinant_from_any_start(seed):
    rng = np.random.default_rng(seed)
    rows = rng.normal(size=(20, 2, 5)) * rng.uniform(0.05, 3.0, 5)
    start = rng.choice(20, size=6, replace=False)
    plan = exchange(rows, start)
    assert len(plan) == 6 and len(set(plan.tolist())) == 6
    assert _log_det(rows[plan]) >= _log_det(rows[start]) - 1e-12


@pytest.mark.parametrize("seed", range(10))
def test_d_optimal_finds_the_brute_force_optimum_of_small_problems(seed):
    """12 candidates, plans of 4: every one of the 495 plans tried."""
    rng = np.random.default_rng(100 + seed)
    rows = rng.normal(size=(12, 2, 4)) * np.array([2.0, 1.0, 0.5, 0.2])
    best = max(_log_det(rows[list(c)]) for c in itertools.combinations(range(12), 4))
    plan = d_optimal(rows, 4)
    assert _log_det(rows[plan]) == pytest.approx(best, abs=1e-9)
    greedy, _, _ = greedy_selection(rows, 4)
    assert _log_det(rows[plan]) >= _log_det(rows[greedy]) - 1e-12


def test_pose_count_is_the_greedy_step_where_the_last_determinable_parameter_meets_it(
    random_rows,
):
    names = tuple("abcdef")
    count = poses_needed(random_rows, names, 0.3)

    def ratio(indices):
        return np.sqrt(np.diag(np.linalg.inv(information_matrix(random_rows[indices]))))

    ratio_all = ratio(np.arange(40))
    assert set(count.determinable) == {n for n, r in zip(names, ratio_all, strict=True) if r <= 0.3}
    assert 0 < len(count.determinable) < 6
    order, _, _ = greedy_selection(random_rows, 40)
    for name, n in count.needed.items():
        if n is None:
            continue
        j = names.index(name)
        assert ratio(order[:n])[j] <= 0.3 < (ratio(order[: n - 1])[j] if n > 1 else 1)
    assert count.n_poses == max(
        max(v for v in count.needed.values() if v), minimum_poses(random_rows)
    )
    assert np.all(ratio(count.indices)[np.isin(names, count.determinable)] <= 0.3)
    assert _log_det(random_rows[count.indices]) >= _log_det(random_rows[order[: count.n_poses]])


def test_pose_count_when_no_parameter_can_reach_the_target():
    rows = np.full((4, 2, 3), 0.01)  # a thousandth of the prior's information per pose
    count = poses_needed(rows, ("a", "b", "c"), 0.5)
    assert count.n_poses == 0 and count.determinable == ()
    assert len(count.indices) == 0


@pytest.mark.parametrize("target", [0.0, 1.0, 1.5])
def test_pose_count_refuses_a_target_outside_zero_to_one(random_rows, target):
    with pytest.raises(InputError, match="target std"):
        poses_needed(random_rows, tuple("abcdef"), target)
