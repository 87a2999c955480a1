"""The polish never hands the last check a point it knows misses its margins, and a printed
wall no point within the bounds thickens ends the repair."""

import numpy as np

from reflector_opt.optimiser._polish import _PoseFields
from reflector_opt.optimiser._printed_walls import LinearWalls


class _Hand(_PoseFields):
    """:class:`_PoseFields` over hand-made fields: point → (resolutions, margins)."""

    def __init__(self, fields):
        self.cache, self.points = {}, {}
        for u, f in fields:
            u = np.array(u, dtype=float)
            self.cache[u.tobytes()] = None if f is None else tuple(map(np.array, f))
            self.points[u.tobytes()] = u


# a near miss: SLSQP's last point misses a margin by 2e-4 at the best resolution seen
LAST, MISSED = np.array([0.4, 0.6]), ([0.08, 0.07], [0.01, -2e-4])
FEASIBLE_WORSE, FEASIBLE_BETTER = ([0.10, 0.09], [0.01, 0.02]), ([0.09, 0.085], [0.0, 0.3])


def _near_miss():
    return _Hand(
        [
            ([0.5, 0.5], FEASIBLE_WORSE),
            ([0.45, 0.55], FEASIBLE_BETTER),
            (LAST, MISSED),
            ([0.3, 0.3], None),
        ]
    )


def test_a_missed_last_point_gives_way_to_the_best_feasible_one():
    fields = _near_miss()
    # by hand: two points meet every margin, worst resolutions 0.10 and 0.09: the second
    np.testing.assert_array_equal(fields.best(LAST, None), [0.45, 0.55])
    assert fields.rank(LAST.tobytes(), None) == (2e-4, 0.08)
    assert fields.rank(np.array([0.3, 0.3]).tobytes(), None) == (np.inf, np.inf)


def test_a_feasible_last_point_is_kept():
    fields = _near_miss()
    u = np.array([0.5, 0.5])  # meets every margin, though another point has a better resolution
    np.testing.assert_array_equal(fields.best(u, None), u)


def test_with_no_feasible_point_the_least_miss_wins():
    fields = _Hand([([0.1, 0.1], ([0.05], [-0.3])), (LAST, ([0.2], [-0.01]))])
    np.testing.assert_array_equal(fields.best(np.array([0.1, 0.1]), None), LAST)


def test_the_walls_model_counts_in_the_miss():
    # a wall 1.2 mm at u0 = 0 thinning by 1 mm per unit of u0, limit 0.6: met where u0 <= 0.6
    walls = LinearWalls(
        np.zeros(2), np.array([1.2]), np.array([[-1.0, 0.0]]), ("w",), np.array([0.6])
    )
    np.testing.assert_array_equal(_near_miss().best(LAST, walls), [0.45, 0.55])
    # the better point moved to u0 = 0.65 misses the wall by 0.05 mm: the worse one wins
    moved = _Hand([([0.5, 0.5], FEASIBLE_WORSE), ([0.65, 0.55], FEASIBLE_BETTER), (LAST, MISSED)])
    np.testing.assert_array_equal(moved.best(LAST, walls), [0.5, 0.5])
    miss, _ = moved.rank(np.array([0.65, 0.55]).tobytes(), walls)
    assert abs(miss - 0.05) < 1e-12


def test_a_wall_no_point_reaches_is_named():
    at = np.array([0.5, 0.25])
    # by hand: the best corner of the box adds 0.2·0.5 + 0.1·0.25 = 0.125 → 0.625 < 0.8;
    # the second wall's slopes reach 0.5 + 0.4·0.5 + 0.4·0.75 = 1.0 ≥ 0.8; the third does
    # not move at all (a zero slope: set by the CAD parameters)
    walls = LinearWalls(
        at,
        np.array([0.5, 0.5, 0.7]),
        np.array([[0.2, -0.1], [0.4, 0.4], [0.0, 0.0]]),
        ("shallow", "steep", "fixed"),
        np.full(3, 0.8),
    )
    assert walls.unreachable() == ("shallow", "fixed")
    # just reachable: the limit at the best corner's value
    exact = LinearWalls(at, np.array([0.5]), np.array([[0.2, -0.1]]), ("w",), np.array([0.625]))
    assert exact.unreachable() == ()
