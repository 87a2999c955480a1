"""The drift front: which points are dominated, by hand."""

from reflector_opt.optimiser.drift_front import DriftPoint, _mark_dominated


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
