"""The studies' driver: variants of a problem, their errors, warm starts and progress."""

from types import SimpleNamespace

import pytest

import reflector_opt.optimiser._studies as studies
from reflector_opt.util._errors import InputError, NoDesignError


def _fake_optimise(problem, *, budget, progress, initial, seed=0, **kwargs):
    """A search that reports half-way, fails for a margin of 0.3 and otherwise 'finds' the
    design {"m": margin, "from": the warm start's margin}."""
    progress(0.5, "searching")
    if problem == 0.3:
        raise NoDesignError("distance window: no design")
    start = None if initial is None else initial["m"]
    evaluation = SimpleNamespace(values={"m": problem, "from": start})
    return SimpleNamespace(evaluation=evaluation, objective=10 * problem, seed=seed)


def _vary(margin):
    if margin < 0:
        raise InputError("distance_margin_mm: must not be negative")
    return margin


def test_variants_run_in_order_each_warm_started_from_the_ones_before(monkeypatch):
    monkeypatch.setattr(studies, "optimise", _fake_optimise)
    shown = []
    found = studies.optimise_variants(
        [("a", 0.2), ("b", -1.0), ("c", 0.3), ("d", 0.1)],
        _vary,
        initial=lambda done: next((v.values for v in reversed(done) if v.error is None), None),
        figures=lambda result, problem: {"twice": 2 * problem},
        progress=lambda fraction, message: shown.append((fraction, message)),
    )
    assert [v.label for v in found] == ["a", "b", "c", "d"]
    assert found[0].values == {"m": 0.2, "from": None} and found[0].figures == {"twice": 0.4}
    # refused before any search: no problem, its message as the reason
    assert found[1].problem is None and found[1].reason.startswith("distance_margin_mm")
    assert isinstance(found[2].error, NoDesignError) and found[2].result is None
    assert found[2].figures == {}
    assert found[3].values == {"m": 0.1, "from": 0.2}  # from the last variant with a design
    # each variant's half-way is its quarter of the whole, named by its label
    assert shown == [(0.125, "a: searching"), (0.625, "c: searching"), (0.875, "d: searching")]


def test_one_variant_runs_here_with_the_executor_for_its_starts(monkeypatch):
    seen = {}

    def optimise(problem, **kwargs):
        seen.update(kwargs)
        return _fake_optimise(
            problem,
            **{k: kwargs[k] for k in ("seed", "budget", "initial")},
            progress=kwargs["progress"],
        )

    monkeypatch.setattr(studies, "optimise", optimise)
    executor = object()
    (only,) = studies.optimise_variants(
        [("a", 0.2)], _vary, seed=7, starts=3, executor=executor, initial={"m": 0.5}
    )
    assert only.result.seed == 7 and only.values == {"m": 0.2, "from": 0.5}
    assert seen["starts"] == 3 and seen["executor"] is executor


@pytest.mark.parametrize("count", [2, 3])
def test_independent_variants_are_tasks_of_the_executor_in_order(monkeypatch, count):
    """Several variants without a chained warm start go to in_tasks, each one task, and come
    back in their order, refused ones kept in place."""
    calls = []

    def in_tasks(fn, items, budget, executor, progress):
        calls.append((len(items), budget.workers, executor))
        return [studies.Variant(v.label, v.value, v.problem, result="done") for v in items]

    monkeypatch.setattr(studies, "in_tasks", in_tasks)
    values = [("refused", -1.0)] + [(f"v{k}", 0.1 * k) for k in range(count)]
    found = studies.optimise_variants(values, _vary, executor="pool")
    assert [v.label for v in found] == [label for label, _ in values]
    assert found[0].result is None and all(v.result == "done" for v in found[1:])
    assert calls == [(count, 2, "pool")]  # the default budget's two workers, the executor
