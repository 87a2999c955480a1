"""Notebook displays: a one-screen repr and an escaped HTML table of the key figures."""

import dataclasses
import html

import pytest

from reflector_opt.design import SensorPlacement
from reflector_opt.model._forward import Response, respond
from reflector_opt.optimiser import Problem, SearchBudget
from reflector_opt.optimiser._result import OptimisationResult
from tests.optimise.points import POINT  # a feasible point of the default problem

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


def _tolerance_study(samples=64):
    """A study as run_study makes it, from drawn records (64 gave a repr of 87,000 characters)."""
    import numpy as np

    from reflector_opt.tolerance import Targets, Tolerances
    from reflector_opt.tolerance._statistics import summarise
    from reflector_opt.tolerance._study import ToleranceStudy

    rng = np.random.default_rng(1)
    records = []
    for i in range(samples):
        rms = float(rng.uniform(0.3, 1.4))
        records.append(
            {
                "index": i,
                **{f"d_{k}_mm": float(rng.normal()) for k in range(24)},  # the draw's columns
                "status": "ok",
                "window_kept": True,
                "distance_margin_mm": float(rng.uniform(0.1, 0.3)),
                "resolution_pitch_deg": 0.16,
                "resolution_roll_deg": 0.16,
                "wall_min_mm": 0.85,
                "rms_pitch_deg": rms,
                "rms_roll_deg": rms / 2,
                "max_pitch_deg": 2.5 * rms,
                "max_roll_deg": 1.2 * rms,
                "misfit_rms_deg": 0.4,
            }
        )
    oat = [
        {"tolerance": name, "mean_deg": 0.5 + d, "p95_deg": 0.6, "mean_increase_deg": d}
        for name, d in (("none", 0.0), ("gain", 0.012), ("offset_v", 0.031))
    ]
    sobol = {
        "rows": 8,
        "groups": [
            {"tolerance": "gain", "first": 0.1, "first_ci": [0, 0.3], "total": 0.2},
            {"tolerance": "offset_v", "first": 0.5, "first_ci": [0.3, 0.7], "total": 0.62},
        ],
    }
    summary = summarise(records, Targets(), nominal_margin_mm=0.25)
    return ToleranceStudy(records, records[0], summary, oat, sobol, Tolerances(), Targets(), seed=7)


def test_tolerance_study_repr_is_one_screen_with_the_key_figures():
    study = _tolerance_study()
    assert len(repr(study.records)) > 50_000  # what the repr used to show
    text = repr(study)
    _one_screen(text)
    s = study.summary
    low, high = (f"{100 * v:.3g}%" for v in s["yield_interval"]["all"])
    assert text.startswith(
        f"ToleranceStudy: 64 units (seed 7), yield {100 * s['yield']['all']:.3g}% "
        f"(95% interval {low} to {high})"
    )
    rms = s["distributions"]["rms_pitch_deg"]
    assert f"RMS error: pitch median {rms['median']:.3g}°, p95 {rms['p95']:.3g}°" in text
    assert f"{s['required_margin_mm']['value']:.3g} mm in 99% of units" in text
    assert "largest offset_v: mean worse RMS error 0.031° above none (2 tolerances)" in text
    assert "Sobol indices: largest total offset_v 0.62 (8 rows)" in text
    assert "9 active: reflector_radius_mm, centre_offset_mm" in text and "and 5 more" in text
    page = study._repr_html_()
    assert len(page) < 3 * MAX_CHARS and "<th" in page and "0.031°" in page


def test_calibration_result_repr_is_one_screen_with_the_key_figures(design):
    from reflector_opt.calibration._simulation import simulate_calibration

    result = simulate_calibration(design, step_deg=3.0, n_validation=500)
    text = repr(result)
    _one_screen(text)
    rms, worst = result.total.rms_deg, result.total.max_deg
    assert text.startswith(
        f"CalibrationResult: eq6, RMS error pitch {rms[0]:.3g}°, roll {rms[1]:.3g}°"
    )
    assert f"max error: pitch {worst[0]:.3g}°, roll {worst[1]:.3g}°" in text
    assert "121 calibration poses on a 3° grid, 500 validation poses" in text
    assert "[" not in text and "array" not in text  # no raw arrays
    page = result._repr_html_()
    assert f"{rms[0]:.3g}°" in page and "<th" in page and len(page) < 2 * MAX_CHARS


def test_problem_repr_is_one_screen_with_the_key_figures():
    problem = Problem(specular_fraction_range=(0.0, 0.3), distance_margin_mm=0.15)
    text = repr(problem)
    _one_screen(text)
    assert text.startswith(
        "Problem: the worst 1σ resolution (imbalance weight 0.25) over 7 free variables"
    )
    assert "sensor: NJL5901R-2, usable 0.5 to 3 mm" in text
    assert "worst case over specular fraction 0 to 0.3" in text
    assert "gap_mm 0.5 to 3" in text and "fixed: centre_across_mm = 0" in text
    assert "distance margin 0.15 mm" in text
    page = problem._repr_html_()
    assert "gap_mm 0.5 to 3" in page and "<th" in page and len(page) < 2 * MAX_CHARS
    assert problem == Problem(specular_fraction_range=(0.0, 0.3), distance_margin_mm=0.15)


def test_built_unit_repr_is_one_screen_with_its_geometry_and_physics(design):
    from reflector_opt.tolerance._builtunit import build_unit
    from reflector_opt.tolerance._model_form import ModelForm

    unit = build_unit(design, 3, model_form=ModelForm().only("subsurface_mm"))
    text = repr(unit)
    assert len(text) < 600 and len(repr(unit.coefficients)) > 1000  # not the coefficients
    assert text.startswith("BuiltUnit #3: 2 sensors")
    assert f"{unit.design.reflector.radius_mm:.4f} mm" in text
    assert f"subsurface_mm {ModelForm().subsurface_mm}" in text
    assert "<table>" in unit._repr_html_()


def test_unit_calibration_repr_names_its_cross_validated_error(tmp_path):
    from reflector_opt.calibration._unit_calibration import calibrate_csv
    from tests.labfiles import write_lab_files

    write_lab_files(tmp_path)
    first = calibrate_csv(tmp_path / "data.csv", folds=3)[0]
    text = repr(first)
    rms = first.cross_validation["rms_deg"]
    assert text.startswith("UnitCalibration of unit '1'") and len(text) < 400
    assert f"{rms[0]:.3g}°, {rms[1]:.3g}°" in text
    assert html.escape("'1'") in first._repr_html_()


def test_a_printed_run_shows_what_its_command_prints():
    from dataclasses import dataclass

    from reflector_opt.util._display import Printed

    @dataclass(frozen=True, repr=False)
    class Run(Printed):
        value: float

        def text(self):
            return f"value <{self.value:g}> & more\nsecond line"

    run = Run(2.5)
    assert repr(run) == "value <2.5> & more\nsecond line"
    assert run._repr_html_() == "<pre>value &lt;2.5&gt; &amp; more\nsecond line</pre>"


def test_every_command_run_with_a_text_displays_it():
    """The workflow runs that carry the command's printed summary show it as their repr."""
    import reflector_opt.workflow as workflow
    from reflector_opt.util._display import Printed

    runs = [getattr(workflow, name) for name in workflow.__all__ if name.endswith("Run")]
    printed = [run for run in runs if "text" in vars(run)]
    assert len(printed) >= 8
    for run in printed:
        if run.__name__ != "CorrectRun":  # its notebook table is its own (the figures)
            assert issubclass(run, Printed) and run.__repr__ is Printed.__repr__, run


def test_more_rows_counts_what_the_summary_leaves_out():
    from reflector_opt.util._display import more_rows

    assert more_rows(12, 10, "levels") == [("…", "2 more levels")]
    assert more_rows(10, 10, "levels") == []
    assert more_rows(3, 10, "levels") == []
