"""The segment: the fewest units a bearing permits, each unit's share of the range, and the
tip errors of built units against the prediction's own segment sweep."""

import dataclasses
import math

import pytest

from reflector_opt.design import Mechanics, Workspace, default_design
from reflector_opt.design._bearings import (
    get_bearing,
    shipped_bearings,
    square_workspace_deg,
    workspace_tilt_deg,
)
from reflector_opt.model._catalogue import get_part
from reflector_opt.optimiser._problem import Problem
from reflector_opt.optimiser._search import SearchBudget
from reflector_opt.optimiser._segment_choice import (
    choose_segment,
    fewest_units,
    segment_choices,
    segment_mechanics,
    tip_errors,
    unit_workspace,
)
from reflector_opt.optimiser._size import SizeStudy, frontier_point
from reflector_opt.tolerance._prediction import predicted_performance
from reflector_opt.util._dask_pool import dask_cluster
from reflector_opt.util._errors import InputError


def test_the_largest_square_a_tilt_permits_by_hand_and_against_the_corner_tilt():
    # cos 16° = 0.961262, √ = 0.980440, arccos = 11.351°
    assert square_workspace_deg(16.0) == pytest.approx(11.351, abs=1e-3)
    w = square_workspace_deg(13.0)
    assert workspace_tilt_deg((-w, w), (-w, w)) == pytest.approx(13.0, abs=1e-9)


@pytest.mark.parametrize(("range_deg", "units"), [(90, 8), (60, 6), (11.3, 1), (11.4, 2)])
def test_the_fewest_units_cover_the_range_within_the_tilt_and_one_fewer_does_not(range_deg, units):
    assert fewest_units(range_deg, shipped_bearings()) == units
    tilt = get_bearing("GE4E").tilt_deg  # the catalogue's most tilting bearing
    w = unit_workspace(range_deg, units, 0.5)
    assert workspace_tilt_deg(w.pitch_deg, w.roll_deg) <= tilt
    if units > 1:
        s = range_deg / (units - 1)
        assert workspace_tilt_deg((-s, s), (-s, s)) > tilt
    # the GE 6 E alone (13°, square ±9.2°) needs more: ⌈90 / 9.21⌉ = 10
    assert fewest_units(90, [get_bearing("GE6E")]) == 10


@pytest.mark.parametrize(("bad", "fragment"), [(120, "outside (0, 90]"), (math.nan, "finite")])
def test_a_range_no_number_of_units_covers_is_refused(bad, fragment):
    with pytest.raises(
        InputError, match=r"^--segment-range-deg: .*" + fragment.replace("(", r"\(")
    ):
        fewest_units(bad, shipped_bearings())


def test_the_segment_mechanics_and_a_link_shorter_than_a_unit():
    m = segment_mechanics(Mechanics(), 8, 20.0)
    assert (m.n_units, m.link_length_mm) == (8, 20.0)
    assert segment_mechanics(Mechanics(), 5, None).link_length_mm == 18.0
    with pytest.raises(InputError, match="--link-mm: 10 mm is less than the unit's height, 12"):
        segment_mechanics(Mechanics(), 8, 10.0)


def test_tip_errors_agree_with_the_predictions_segment_of_the_same_built_units():
    # Two units of ±10°: a ±20° segment. predicted_performance sweeps the same built units
    # (same seeds, the recommended form on the recommended plan) to min(60°, 2 × 10°) = 20°
    design = default_design()
    design = design.replace(
        workspace=Workspace((-10.0, 10.0), (-10.0, 10.0), step_deg=0.5),
        mechanics=dataclasses.replace(design.mechanics, n_units=2),
    )
    ours = tip_errors(design, 20.0, seed=3)
    theirs = predicted_performance(design, seed=3).segment_recommended
    for axis in ("pitch", "roll"):
        assert ours["paper_motion"][axis]["amplitude_deg"] == 20.0
        mine, other = ours["paper_motion"][axis]["predicted"], theirs[axis]["predicted"]
        assert mine == pytest.approx(other, rel=1e-12)
        assert ours["range"][axis]["predicted"] == pytest.approx(other, rel=1e-12)
        # a tip 2 × 18 mm out: its position error is at most the arc of its orientation error
        # at the far link plus that at the near one, 18 mm × (2 + 1) × the angle, radians
        bound = 18.0 * 3 * math.radians(mine["orientation_max_deg"])
        assert 0 < mine["position_max_mm"] <= bound
    assert len(ours["unit_rms_deg"]) == 2


def test_the_segment_chosen_is_the_fewest_units_no_choice_beats_at_the_tip():
    rows = [
        {"n_units": 8, "objective_deg": 0.09, "orientation_rms_deg": 0.5, "position_rms_mm": 1.0},
        {"n_units": 9, "objective_deg": 0.07, "orientation_rms_deg": 0.4, "position_rms_mm": 0.9},
        {"n_units": 10, "objective_deg": 0.05, "orientation_rms_deg": 0.45, "position_rms_mm": 0.8},
    ]
    choices = [(r, {}, object()) for r in rows]
    assert choose_segment(choices)[0]["n_units"] == 9  # 9 beats 8 in both; 10 does not beat 9
    # better orientation but a worse position: the fewer units stay
    worse_position = [(dict(rows[0], position_rms_mm=0.85), {}, object()), choices[1]]
    assert choose_segment(worse_position)[0]["n_units"] == 8
    assert choose_segment(choices, target_deg=0.06)[0]["n_units"] == 10
    with pytest.raises(InputError, match="no choice of units has a design"):
        choose_segment([(rows[0], None, None)])


def test_the_choices_on_a_dask_cluster_are_those_of_local_processes():
    """``smallest --scheduler``: the segment's choices run as tasks of the frontier's
    executor, and a Dask LocalCluster gives the choices local processes give."""
    distributed = pytest.importorskip("distributed")
    study = SizeStudy(
        Problem(workspace=Workspace((-11.0, 11.0), (-11.0, 11.0), step_deg=0.5)),
        shipped_bearings(),
        budget=SearchBudget(popsize=5, maxiter=8, workers=2),
        starts=1,
    )
    part = get_part("VCNT2020")
    row, _, result = frontier_point(study, part, 22.0)
    # ±11° on the GE 4 E: one unit of ±11°, then two of ±5.5° optimised afresh (with this
    # small budget no design of the two passes its printed walls: a row without one)
    local = segment_choices(study, part, row, result.design, 11.0, 20.0, count=2)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None, host="127.0.0.1"
    ) as cluster:
        remote = segment_choices(
            study,
            part,
            row,
            result.design,
            11.0,
            20.0,
            2,
            None,
            dask_cluster(cluster.scheduler_address),
        )
    assert [c[0]["n_units"] for c in local] == [1, 2]
    assert [c[0]["unit_workspace_deg"] for c in local] == [11.0, 5.5]
    assert local[0][2].mechanics.n_units == 1 and local[0][1] is not None
    for (a, errors_a, design_a), (b, errors_b, design_b) in zip(local, remote, strict=True):
        assert {k: v for k, v in a.items() if k != "seconds"} == {
            k: v for k, v in b.items() if k != "seconds"
        }
        assert errors_a == errors_b
        assert (design_a is None) == (design_b is None)
        if design_a is not None:
            assert design_a.replace(predicted={}) == design_b.replace(predicted={})
