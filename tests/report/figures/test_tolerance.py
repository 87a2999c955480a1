"""The tolerance study's figures: the errors' histograms, the yield bars and the sensitivities,
drawn from a hand-made study of three units."""

from types import SimpleNamespace

import numpy as np
import pytest

from reflector_opt.report.figures._tolerance import error_histograms, sensitivity_bars, yield_bars
from tests.report.figures.drawing import render


def _record(status, rms, worst):
    return {
        "status": status,
        **{f"rms_{a}_deg": rms for a in ("pitch", "roll")},
        **{f"max_{a}_deg": worst for a in ("pitch", "roll")},
    }


def _group(name, first, total, first_ci, total_ci):
    return {
        "tolerance": name,
        "first": first,
        "total": total,
        "first_ci": first_ci,
        "total_ci": total_ci,
    }


@pytest.fixture
def study():
    """Three units (one failed), targets 0.5° RMS and 1° max, both sensitivities."""
    return SimpleNamespace(
        records=[_record("ok", 0.2, 0.6), _record("ok", 0.4, 1.2), _record("failed", 0, 0)],
        targets=SimpleNamespace(rms_deg=0.5, max_deg=1.0),
        summary={"yield": {"window": None, "rms": 1.0, "max": 0.5, "all": 0.5}},
        one_at_a_time=[
            {"tolerance": "none", "mean_increase_deg": 0.0},
            {"tolerance": "gap", "mean_increase_deg": 0.03},
            {"tolerance": "tilt", "mean_increase_deg": None},
        ],
        sobol={
            "groups": [
                _group("gap", 0.6, 0.7, [0.5, 0.7], [0.6, 0.8]),
                _group("tilt", -0.1, None, [-0.2, -0.15], [None, None]),
            ],
            "outside": [{"tolerance": "tilt", "index": "first"}],
            "confidence": 0.95,
            "rows": 64,
        },
    )


def test_the_histograms_count_the_units_that_were_computed(study):
    fig = render(lambda: error_histograms(study))
    rms, worst = fig.axes
    assert fig._suptitle.get_text() == "3 simulated units"
    assert [sum(p.get_height() for p in c) for c in rms.containers] == [2, 2]  # ok units only
    assert rms.lines[0].get_xdata()[0] == 0.5 and worst.lines[0].get_xdata()[0] == 1.0
    assert rms.get_xlabel() == "calibrated RMS error (°)"


def test_the_yield_bars_leave_out_a_target_not_set(study):
    ax = render(lambda: yield_bars(study)).axes[0]
    assert [t.get_text() for t in ax.get_xticklabels()] == ["rms", "max", "all"]
    assert [p.get_height() for p in ax.patches] == [1.0, 0.5, 0.5]
    assert ax.get_title() == "targets: RMS ≤ 0.5°, max ≤ 1°"


def test_the_sensitivities_draw_each_tolerance_and_the_sobol_intervals(study):
    fig = render(lambda: sensitivity_bars(study))
    alone, sobol = fig.axes
    assert [p.get_width() for p in alone.patches] == [0.03, 0.0]  # "none" left out, None as 0
    assert "95 % interval, 64 rows" in sobol.get_xlabel()
    widths = [p.get_width() for p in sobol.patches]
    assert widths[0] == 0.7 and np.isnan(widths[1])  # tilt's total not computed: no bar
    assert widths[2:] == [0.6, -0.1]  # an index below 0 is drawn, not clipped
    red = [c for c in sobol.collections if tuple(c.get_edgecolor()[0][:3]) == (1.0, 0.0, 0.0)]
    assert len(red) == 1  # tilt's first-order index lies outside its interval


def test_without_sensitivities_the_figure_is_empty(study):
    study.one_at_a_time, study.sobol = [], None
    assert render(lambda: sensitivity_bars(study)).axes == []
