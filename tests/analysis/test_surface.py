"""A design's worst-case resolution against its surface's specular fraction (analysis.surface)."""

from dataclasses import replace

import pytest

from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.analysis._surface import resolution_against_surface
from reflector_opt.design import default_design

STEP_DEG = 10.0  # a coarse pose grid keeps the sweep fast


def test_each_row_is_the_design_with_that_fraction():
    design = default_design()
    own = design.reflector.specular_fraction
    rows = resolution_against_surface(design, fractions=(0.0, own, 1.0), step_deg=STEP_DEG)
    assert [row["specular_fraction"] for row in rows] == [0.0, own, 1.0]
    # The row at the design's own fraction is the design's own resolution.
    metrics = evaluate_metrics(design, STEP_DEG)
    assert rows[1]["worst_pitch_deg"] == pytest.approx(metrics.worst_pitch_deg, rel=1e-12)
    assert rows[1]["worst_roll_deg"] == pytest.approx(metrics.worst_roll_deg, rel=1e-12)
    # Independent of the row at f = 1: a fully specular variant built by hand.
    mirror = design.replace(reflector=replace(design.reflector, specular_fraction=1.0))
    assert rows[2]["worst_roll_deg"] == pytest.approx(
        evaluate_metrics(mirror, STEP_DEG).worst_roll_deg, rel=1e-12
    )
    for row in rows:
        assert row["worst_deg"] == max(row["worst_pitch_deg"], row["worst_roll_deg"])
    # The surface changes the resolution: a sweep that ignored f would give equal rows.
    assert rows[0]["worst_deg"] != pytest.approx(rows[2]["worst_deg"], rel=1e-3)
