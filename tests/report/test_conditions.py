"""The report's "In use" section and the figures in use every command opens with."""

import dataclasses
import json

import numpy as np
import pytest

from reflector_opt.analysis._budget import drift_sensitivity, error_budget
from reflector_opt.design import default_design, load_design
from reflector_opt.design._conditions import Conditions
from reflector_opt.optimiser._conditions import pose_totals, worst_totals
from reflector_opt.report._conditions import (
    BUDGET_FIGURE,
    budget_in_use,
    budget_maps_figure,
    conditions_blocks,
    in_use_block,
)
from reflector_opt.report._in_use import DEFAULT_CONDITIONS, in_use_lines

EXAMPLE = "tests/data/design_6c47a9f.json"  # the white-noise sample design


def test_the_section_holds_the_drift_the_budget_table_and_its_maps():
    figures = {}
    conditions = Conditions().replace(temperature_range_k=5.0)
    blocks = conditions_blocks(
        default_design(), figures, error_budget(default_design(), conditions)
    )
    drift_table, budget_table = [b for b in blocks if b[0] == "table"]
    common = next(r for r in drift_table[2] if r[0] == "common")
    expected = drift_sensitivity(default_design())["common"].pitch_rms_deg
    assert float(common[1]) == pytest.approx(expected, abs=5e-4)
    names = [row[0] for row in budget_table[2]]
    assert names[-1] == "total" and "temperature" in names
    assert ("img", BUDGET_FIGURE) == blocks[-1][:2] and BUDGET_FIGURE in figures
    budget = error_budget(default_design(), conditions)
    shown = [ax for ax in budget_maps_figure(budget).axes if ax.get_visible() and ax.get_title()]
    costing = [n for n, m in budget.maps.items() if m.max() > 1e-6]
    assert len(shown) == len(costing)  # one map per source that costs anything
    assert any(ax.get_title().startswith("temperature") for ax in shown)
    quiet = dataclasses.replace(budget, maps={n: 0.0 * m for n, m in budget.maps.items()})
    figure = budget_maps_figure(quiet)  # no source costs anything: said, not a division by 0
    assert not figure.axes and "No source costs anything" in figure.texts[0].get_text()


@pytest.fixture(scope="module")
def example_in_use():
    return in_use_block(load_design(EXAMPLE))


def test_the_figures_are_the_budget_s_in_the_default_conditions(example_in_use):
    """Worst case and RMS of an independently called budget in ``Conditions()``: the worst case
    per angle is the largest pose total, the RMS sqrt(mean over poses of the worse angle²)."""
    budget = error_budget(load_design(EXAMPLE), Conditions())
    totals = pose_totals(budget)
    pitch, roll = worst_totals(budget)
    assert example_in_use.worst_pitch_deg == pytest.approx(pitch, rel=1e-12)
    assert example_in_use.worst_roll_deg == pytest.approx(roll, rel=1e-12)
    assert example_in_use.worst_case_deg == pytest.approx(max(pitch, roll), rel=1e-12)

    def rms_of(totals):
        worse = np.maximum(totals[..., 0], totals[..., 1]).ravel()
        return np.sqrt(np.sum(worse**2) / worse.size)

    assert example_in_use.rms_deg == pytest.approx(rms_of(totals), rel=1e-12)
    # the comparison fails on a doubled source, or on the mean taken for the RMS
    doubled = np.sqrt(totals**2 + 3 * budget.maps["temperature"] ** 2)
    assert example_in_use.rms_deg != pytest.approx(rms_of(doubled), rel=1e-3)
    assert example_in_use.worst_case_deg != pytest.approx(doubled.max(), rel=1e-3)
    mean = np.mean(np.max(totals, axis=-1))
    assert example_in_use.rms_deg != pytest.approx(mean, rel=1e-3)
    assert example_in_use.median_deg < example_in_use.rms_deg < pitch
    # the bench figures: 1.581° for this design, 1.367° the default's (its centre 1.4 mm below O)
    assert example_in_use.worst_case_deg == pytest.approx(1.581, abs=5e-4)
    base = example_in_use.baseline
    assert base.worst_case_deg == pytest.approx(1.3665, abs=5e-4)
    assert example_in_use.improvement == pytest.approx(1.3665 / 1.581, abs=1e-3)
    assert example_in_use.improvement_median == pytest.approx(
        base.median_deg / example_in_use.median_deg, rel=1e-12
    )
    assert example_in_use.white_noise_floor_deg == pytest.approx(0.08851, abs=1e-5)


def test_the_default_conditions_are_named_and_a_file_by_its_path(example_in_use, tmp_path):
    assert example_in_use.conditions_source == DEFAULT_CONDITIONS
    assert example_in_use.conditions == Conditions().to_dict()
    first = in_use_lines(example_in_use)[0]
    assert first.startswith(
        "  in use in the default conditions (docs/conditions.md) (±2 K, dc drive at 1"
    )
    assert "worst case 1.5812° (pitch 1.5812°, roll 1.3849°), RMS " in first
    assert first.endswith("; white-noise floor 0.0885° (worst-case 1σ resolution)")
    path = tmp_path / "warm.toml"
    path.write_text("[conditions]\ntemperature_range_k = 5.0\n")
    budget = budget_in_use(default_design(), str(path))
    assert budget.conditions.temperature_range_k == 5.0
    block = in_use_block(default_design(), str(path), budget)
    assert block.conditions_source == str(path) and block.improvement == 1.0
    assert json.loads(json.dumps(block.to_dict())) == block.to_dict()  # JSON-ready
