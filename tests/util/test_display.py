"""Notebook displays: a one-screen repr and an escaped HTML table of the key figures."""

import dataclasses
import html

import pytest

from reflector_opt.design import SensorPlacement
from reflector_opt.model.forward import Response, respond
from reflector_opt.optimise import Problem, SearchBudget
from reflector_opt.optimise.result import OptimisationResult
from tests.optimise.test_search import POINT  # a feasible point of the default problem

#: One screen: at most this many lines and characters.
MAX_LINES = 12
MAX_CHARS = 1200


def _one_screen(text):
    assert len(text.splitlines()) <= MAX_LINES and len(text) <= MAX_CHARS, text


@pytest.fixture(scope="module")
def result():
    """An optimiser result as the search makes it (without running the search), 1° grid."""
    problem = Problem()
    evaluation = problem.evaluate(POINT, 1.0)
    baseline = problem.evaluate_design(problem.baseline_design(), 1.0)
    found = OptimisationResult(
        design=None,
        evaluation=evaluation,
        baseline=baseline,
        seed=3,
        history=[{"generation": g, "best": 0.2, "spread": 0.1} for g in range(12)],
        evaluations={"search": 840, "polish": 60, "verify": 1, "baseline": 1},
        seconds={"search": 12.5, "polish_and_verify": 3.25},
        budget=SearchBudget(),
        tightening={"distance_margin_mm": 0.01},
    )
    return dataclasses.replace(found, design=evaluation.design.replace(predicted=found.predicted()))


def test_design_repr_is_one_screen_with_the_key_figures(result):
    design = result.design  # with the optimiser's full predicted block
    text = repr(design)
    _one_screen(text)
    r = design.reflector
    assert f"sphere radius {r.radius_mm:.3f} mm" in text
    assert "S1" in text and "S2" in text and "mm" in text and "°" in text
    assert f"objective {result.objective:.3g}°" in text
    page = design._repr_html_()
    assert page.startswith("<table>") and f"{r.radius_mm:.3f} mm" in page
    assert "workspace" in page and "-15 to 15°" in page


def test_design_equality_is_unchanged(design):
    same = design.replace()
    assert same == design and same is not design
    moved = design.replace(reflector=dataclasses.replace(design.reflector, radius_mm=9.1))
    assert moved != design


def test_design_html_escapes_names(design):
    odd = '<S&1 "a">'
    sensors = (dataclasses.replace(design.sensors[0], name=odd), *design.sensors[1:])
    changed = design.replace(sensors=sensors)
    page = changed._repr_html_()
    assert html.escape(odd) in page and odd not in page
    assert odd in repr(changed)


def test_design_with_many_sensors_stays_on_one_screen(design):
    base = design.sensors[0]
    sensors = tuple(
        SensorPlacement(f"S{i}", base.model, base.position_mm, base.axis) for i in range(1, 9)
    )
    text = repr(design.replace(sensors=sensors))
    _one_screen(text)
    assert "S8" in text and "8 sensors" in text


def test_response_repr_is_one_screen(design):
    pitch, roll = design.workspace.grid(1.0)
    response = respond(design, pitch, roll)
    text = repr(response)
    _one_screen(text)
    assert text.startswith("Response: 961 poses (shape (31, 31)) × 2 sensors")
    low, high = response.volts.min(), response.volts.max()
    assert f"{low:.3g} to {high:.3g} V" in text
    assert f"{response.distance_mm.min():.3g} to {response.distance_mm.max():.3g} mm" in text
    page = response._repr_html_()
    assert f"{low:.3g} to {high:.3g} V" in page and "×" in page
    assert repr(respond(design, 0.0, 0.0)).startswith("Response: 1 pose (shape ()) × 2 sensors")
    assert Response.__eq__ is not object.__eq__  # the dataclass's field-wise equality


def test_result_repr_is_one_screen_with_the_key_figures(result):
    text = repr(result)
    _one_screen(text)
    m = result.metrics
    assert f"objective {result.objective:.4g}° (feasible)" in text
    assert f"pitch {m.worst_pitch_deg:.4g}°, roll {m.worst_roll_deg:.4g}°" in text
    assert "seed 3, 12 generations, 902 evaluations, 15.8 s" in text
    assert "distance_margin_mm 0.01" in text
    page = result._repr_html_()
    assert f"{m.worst_pitch_deg:.4g}°" in page and "<th" in page
    assert result == dataclasses.replace(result)  # equality unchanged (field by field)
