"""The report's "In use" section: drift sensitivity always, the budget and its maps too."""

import pytest

from reflector_opt.analysis.budget import drift_sensitivity, error_budget
from reflector_opt.design import default_design
from reflector_opt.design.conditions import Conditions
from reflector_opt.report.conditions import BUDGET_FIGURE, budget_maps_figure, conditions_blocks


def test_without_conditions_only_the_drift_sensitivity():
    figures = {}
    blocks = conditions_blocks(default_design(), figures)
    tables = [b for b in blocks if b[0] == "table"]
    assert len(tables) == 1 and figures == {}
    common = next(r for r in tables[0][2] if r[0] == "common")
    expected = drift_sensitivity(default_design())["common"].pitch_rms_deg
    assert float(common[1]) == pytest.approx(expected, abs=5e-4)


def test_with_conditions_the_budget_table_and_its_maps():
    figures = {}
    conditions = Conditions().replace(temperature_range_k=5.0)
    blocks = conditions_blocks(default_design(), figures, conditions)
    budget_table = [b for b in blocks if b[0] == "table"][1]
    names = [row[0] for row in budget_table[2]]
    assert names[-1] == "total" and "temperature" in names
    assert ("img", BUDGET_FIGURE) == blocks[-1][:2] and BUDGET_FIGURE in figures
    budget = error_budget(default_design(), conditions)
    shown = [ax for ax in budget_maps_figure(budget).axes if ax.get_visible() and ax.get_title()]
    costing = [n for n, m in budget.maps.items() if m.max() > 1e-6]
    assert len(shown) == len(costing)  # one map per source that costs anything
    assert any(ax.get_title().startswith("temperature") for ax in shown)
