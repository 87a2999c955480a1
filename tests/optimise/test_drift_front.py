"""The drift front: which points are dominated, by hand."""

import pytest

from reflector_opt.optimiser._drift_front import DriftPoint, _best_known, _mark_dominated


def test_dominated_points_are_marked_by_hand():
    points = [
        DriftPoint(None, True, drift_deg=0.6, objective_deg=0.09),
        DriftPoint(0.5, True, drift_deg=0.45, objective_deg=0.12),
        DriftPoint(0.4, True, drift_deg=0.40, objective_deg=0.11),  # beats the one above
        DriftPoint(0.3, False, reason="no design"),
        DriftPoint(0.2, True, drift_deg=0.40, objective_deg=0.11),  # equal: not dominated
    ]
    marked = _mark_dominated(points)
    assert [p.dominated for p in marked] == [False, True, False, False, False]


def test_each_level_keeps_the_best_known_design_meeting_its_limit_by_hand():
    """A level takes the best verified design within its limit when its own is worse or
    missing (naming where it came from), keeps its own on a tie, and the white-noise optimum
    stays itself."""
    optimum = DriftPoint(None, True, drift_deg=0.6, objective_deg=0.09, values={"v": 0})
    worse = DriftPoint(0.5, True, drift_deg=0.45, objective_deg=0.12, values={"v": 1})
    good = DriftPoint(0.45, True, drift_deg=0.40, objective_deg=0.11, values={"v": 2})
    missing = DriftPoint(0.42, False, reason="no design")
    tied = DriftPoint(0.41, True, drift_deg=0.41, objective_deg=0.11, values={"v": 4})
    reference = DriftPoint(None, True, drift_deg=0.3, objective_deg=0.115, values={"v": 5})
    kept = _best_known([optimum, worse, good, missing, tied], reference)
    assert kept[0] is optimum and kept[2] is good and kept[4] is tied
    assert kept[1].values == {"v": 2} and kept[1].kept_from == "drift ≤ 0.45°"
    assert kept[1].drift_limit_deg == 0.5 and kept[1].reason is None
    assert kept[3].values == {"v": 2} and kept[3].reason == "no design"
    assert kept[3].drift_limit_deg == 0.42
    alone = _best_known([optimum, missing], reference)[1]
    assert alone.values == {"v": 5} and alone.kept_from == "optimised in the conditions"


@pytest.mark.parametrize("fractions", [(), (0.5, 1.0), (1.5,), (0.0,)])
def test_fractions_outside_the_open_unit_interval_are_refused_before_any_search(fractions):
    """From Python the drift front is reached without ``[pareto]``'s schema (an
    OptimiseConfig built by hand): its own check refuses the level, naming the key."""
    from reflector_opt.optimiser import Problem
    from reflector_opt.optimiser._drift_front import drift_front
    from reflector_opt.util._errors import InputError

    with pytest.raises(InputError, match=r"^drift_fractions: each must lie strictly between"):
        drift_front(Problem(), fractions)
