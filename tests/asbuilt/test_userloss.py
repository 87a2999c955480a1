"""What a user loses on a printed unit (asbuilt.userloss): the unit's figures, the loss of its
margins' shortfall, a batch's figures."""

import math

import numpy as np
import pytest

from reflector_opt.asbuilt._userloss import (
    REQUIRED_MARGIN_MM,
    UnitFigures,
    batch_figures,
    loss_deg,
    unit_figures,
)
from reflector_opt.design import Reflector
from reflector_opt.model._catalogue_fit import flat_peak
from reflector_opt.model._forward import respond

STEP_DEG = 5.0  # a 7 × 7 grid over ±15° keeps the figures fast


def test_loss_by_hand():
    figures = UnitFigures(0.1, 0.05, (0.3, 0.02), (0.5, 0.5), 1.0)
    drawn = UnitFigures(0.1, 0.05, (0.2, 0.2), (0.5, 0.5), 0.05)
    # Targets min(drawn, 0.1 mm) = (0.1, 0.1, 0.1, 0.1, 0.05); only the second window falls
    # short, by 0.08 mm: 0.1 + 0.05 + 1 °/mm × 0.08 mm = 0.23°.
    assert REQUIRED_MARGIN_MM == 0.1
    assert loss_deg(figures, drawn) == pytest.approx(0.23, abs=1e-12)
    assert loss_deg(figures, drawn, penalty_deg_per_mm=2.0) == pytest.approx(0.31, abs=1e-12)
    assert loss_deg(drawn, drawn) == pytest.approx(0.15 + 0.0)  # as drawn: nothing lost


def test_unit_figures_of_the_default_design(design):
    figures = unit_figures(design, step_deg=STEP_DEG)
    # Clearance: the centre (0, 0, −1.4) turned by pitch 15° and roll 15° lies
    # 1.4·sqrt(sin²15° + cos²15° sin²15°) from the axis; 11 mm − (9 mm + that).
    s = math.sin(math.radians(15.0))
    reach = 9.0 + 1.4 * math.sqrt(s**2 + (1 - s**2) * s**2)
    assert figures.clearance_mm == pytest.approx(11.0 - reach, abs=1e-9)
    # Windows and peaks from the Eq 3 distances over the same grid.
    distance = respond(design, *design.workspace.grid(STEP_DEG)).distance_mm.reshape(-1, 2)
    for k, model in enumerate(design.models):
        lo, hi = model.range_mm
        d_min, d_max = distance[:, k].min(), distance[:, k].max()
        assert figures.window_mm[k] == pytest.approx(min(d_min - lo, hi - d_max), abs=1e-9)
        assert figures.peak_mm[k] == pytest.approx(d_min - flat_peak(model, "mirror")[0])
    assert 0.0 < figures.angle_deg < 1.0 and 0.0 < figures.drift_deg < 10.0
    assert figures.to_dict()["window_mm"] == list(figures.window_mm)


def test_a_batch_is_its_units_mean_largest_and_smallest(design):
    larger = design.replace(reflector=Reflector(9.2, (0.0, 0.0, -1.4), 7.5, 0.9, 0.05))
    units = [(design, None), (larger, None)]
    each = [unit_figures(built, step_deg=STEP_DEG) for built, _ in units]
    batch = batch_figures(units, step_deg=STEP_DEG)
    angles = [f.angle_deg for f in each]
    assert batch["angle_deg"] == {"mean": pytest.approx(np.mean(angles)), "max": max(angles)}
    assert batch["clearance_mm"] == min(f.clearance_mm for f in each)
    assert batch["clearance_mm"] == pytest.approx(each[1].clearance_mm)  # 0.2 mm more reach
    assert batch["window_mm"] == np.minimum(each[0].window_mm, each[1].window_mm).tolist()
