"""The Pareto front of resolution against the distance margin."""

import numpy as np
import pytest

from reflector_opt.design import Workspace
from reflector_opt.optimiser import (
    Problem,
    SearchBudget,
)
from reflector_opt.optimiser._pareto import pareto_front
from reflector_opt.report.figures._base import save_figure
from reflector_opt.report.figures._optimiser import pareto_figure


@pytest.mark.slow
def test_pareto_front_trades_resolution_for_margin(tmp_path):
    problem = Problem(workspace=Workspace(step_deg=0.5))
    front = pareto_front(problem, (0.3, 0.0, 1.3), budget=SearchBudget(popsize=5, maxiter=10))
    levels = [p.required_margin_mm for p in front.points]
    assert levels == [0.0, 0.3, 1.3]
    low, high, impossible = front.points
    assert low.feasible and high.feasible and not impossible.feasible
    assert "distance window" in impossible.reason
    assert high.margin_mm >= 0.3 - 1e-9
    assert high.worst_deg > low.worst_deg  # robustness costs resolution
    doc = front.to_dict()
    assert doc["points"][2]["worst_pitch_deg"] is None
    fig = pareto_figure(front)
    assert len(fig.axes[0].lines) >= 2
    save_figure(fig, tmp_path / "pareto.png")
    assert (tmp_path / "pareto.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_pareto_level_keeps_the_better_verified_design_of_the_level_above(monkeypatch):
    """A repaired level that ends worse than the level above takes that level's design."""
    from types import SimpleNamespace

    import reflector_opt.optimiser._pareto as pareto
    import reflector_opt.optimiser._studies as studies

    worst = {0.2: 0.09, 0.1: 0.08, 0.0: 0.085}  # the 0 mm level's repair overshot

    def fake_optimise(problem, seed, budget, progress, initial, **kwargs):
        m = problem.distance_margin_mm
        metrics = SimpleNamespace(
            distance_margin_mm=np.array([m + 0.01]),
            worst_pitch_deg=worst[m],
            worst_roll_deg=worst[m],
        )
        values = {"level": m}
        return SimpleNamespace(
            metrics=metrics, objective=worst[m], evaluation=SimpleNamespace(values=values)
        )

    monkeypatch.setattr(studies, "optimise", fake_optimise)
    front = pareto.pareto_front(Problem(), (0.0, 0.1, 0.2))
    assert [p.objective_deg for p in front.points] == [0.08, 0.08, 0.09]
    zero = front.points[0]
    assert zero.required_margin_mm == 0.0 and zero.values == {"level": 0.1}
    assert zero.margin_mm == pytest.approx(0.11)


def test_in_conditions_each_level_records_its_in_use_worst_case_beside_its_floor(monkeypatch):
    """A front traced in conditions: each point's in-use worst case is its search's budget's,
    in the JSON, the table and the figure beside the white-noise resolution; without
    conditions it is null and the table and figure are as before."""
    from types import SimpleNamespace

    import reflector_opt.optimiser._pareto as pareto
    import reflector_opt.optimiser._studies as studies
    from reflector_opt.workflow._optimise_text import format_pareto

    in_use = {0.1: 1.21, 0.0: 1.12}

    def fake_optimise(problem, seed, budget, progress, initial, with_budget=True, **kwargs):
        m = problem.distance_margin_mm
        metrics = SimpleNamespace(
            distance_margin_mm=np.array([m]), worst_pitch_deg=0.08, worst_roll_deg=0.07
        )
        budget = SimpleNamespace(worst_case_deg=in_use[m]) if with_budget else None
        evaluation = SimpleNamespace(values={"level": m}, budget=budget)
        return SimpleNamespace(metrics=metrics, objective=in_use[m], evaluation=evaluation)

    monkeypatch.setattr(studies, "optimise", fake_optimise)
    front = pareto.pareto_front(Problem(), (0.0, 0.1))
    doc = front.to_dict()
    assert [p["worst_case_deg"] for p in doc["points"]] == [1.12, 1.21]
    assert [p["worst_pitch_deg"] for p in doc["points"]] == [0.08, 0.08]  # kept beside it
    table = format_pareto(front).splitlines()
    assert table[1].endswith("in use (°)") and table[2].split()[-1] == "1.1200"
    fig = pareto_figure(front)
    assert [line.get_label() for line in fig.axes[0].lines][:3] == [
        "pitch",
        "roll",
        "in-use worst case",
    ]
    monkeypatch.setattr(
        studies, "optimise", lambda *a, **k: fake_optimise(*a, **k, with_budget=False)
    )
    plain = pareto.pareto_front(Problem(), (0.0, 0.1))
    assert plain.to_dict()["points"][0]["worst_case_deg"] is None
    assert "in use" not in format_pareto(plain)
    assert len(pareto_figure(plain).axes[0].lines) == 2
