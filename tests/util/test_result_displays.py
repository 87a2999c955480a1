"""Notebook displays of the remaining result objects: one screen, the key figures, HTML escaped.

Each object is built from its own fields (or by the cheap public function that makes it); every
figure the display must name is formatted here from those fields, not copied from the display.
"""

import html
from types import SimpleNamespace

import numpy as np
import pytest

from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.asbuilt._correction import Correction
from reflector_opt.asbuilt._doe import PoseCount
from reflector_opt.asbuilt._estimator import AsBuiltModel
from reflector_opt.asbuilt._patterns import PatternRow
from reflector_opt.asbuilt._planstudy import IdentificationStudy
from reflector_opt.asbuilt._pooling import BatchMean, Direction
from reflector_opt.cad._clearance import ClearanceProof
from reflector_opt.cad._printability import PrintabilityReport
from reflector_opt.model._catalogue import get_part
from reflector_opt.model._catalogue_fit import fit_part
from reflector_opt.model._material_fit import MaterialFit
from reflector_opt.model._measured import CurveFit
from reflector_opt.model._noise import Mismatch
from reflector_opt.optimiser._pareto import ParetoFront, ParetoPoint
from reflector_opt.optimiser._robust import RobustOptions, RobustResult
from reflector_opt.optimiser._sensor_choice import SensorChoice
from reflector_opt.tolerance._config import ToleranceConfig
from reflector_opt.tolerance._planning import PlanPrediction, PlanStudy

#: One screen: at most this many lines and characters.
MAX_LINES = 25
MAX_CHARS = 1500

#: Text that HTML must escape, put into a name or reason of each object.
ODD = '<b&"x">'


def g3(value, unit=""):
    """A figure to 3 significant digits with its unit, as a reader expects it."""
    text = f"{value:.3g}"
    return f"{text}{unit}" if unit in ("", "°") else f"{text} {unit}"


def _check(obj, figures, odd=None):
    """The repr is one screen naming every figure; the HTML table names them and escapes."""
    text = repr(obj)
    assert len(text.splitlines()) <= MAX_LINES and len(text) <= MAX_CHARS, text
    page = obj._repr_html_()
    assert page.startswith("<table>") and "<th" in page
    for figure in figures:
        assert figure in text, (figure, text)
        assert html.escape(figure) in page, (figure, page)
    if odd is not None:
        assert odd in text and html.escape(odd) in page and odd not in page
    return text


@pytest.fixture(scope="module")
def metrics(design):
    return evaluate_metrics(design, 3.0)


def test_design_metrics(metrics):
    m = metrics
    figures = [
        f"{m.n_poses} poses",
        g3(m.worst_pitch_deg, "°"),
        g3(m.worst_roll_deg, "°"),
        g3(m.worst_condition),
        g3(m.wall_min_mm, "mm"),
        g3(m.reach_max_mm, "mm"),
    ]
    for i in range(len(m.distance_min_mm)):
        low, high = m.distance_min_mm[i], m.distance_max_mm[i]
        figures += [f"{low:.3g} to {high:.3g} mm", g3(m.distance_margin_mm[i], "mm")]
        figures.append(f"{m.volts_min[i]:.3g} to {m.volts_max[i]:.3g} V")
    _check(m, figures)


def _rounds(n):
    return tuple(
        {
            "round": k + 1,
            "limit_mm": 0.1 * k,
            "margin_mm": 0.123 + 0.01 * k,
            "required_mm": 0.456 - 0.01 * k,
            "window_yield": 0.91 + 0.01 * k,
            "objective_deg": 0.333 + k,
        }
        for k in range(n)
    )


def robust_result():
    result = SimpleNamespace(design=None)
    return RobustResult(result, _rounds(3), False, RobustOptions(), ToleranceConfig(), 321.0)


def test_robust_result():
    r = robust_result()
    last = r.rounds[-1]
    text = _check(
        r,
        [
            "not converged after 3 rounds",
            g3(last["margin_mm"], "mm"),
            g3(last["required_mm"], "mm"),
            g3(last["window_yield"]),
            g3(last["objective_deg"], "°"),
            g3(r.options.coverage),
            g3(r.rounds[0]["margin_mm"], "mm"),
        ],
    )
    assert f"{r.tolerance.run.samples}" in text


def pareto_front(levels=4):
    points = [
        ParetoPoint(0.05 * k, True, 0.05 * k + 0.01, 0.11 + 0.01 * k, 0.12 + 0.02 * k, 0.5)
        for k in range(levels - 1)
    ]
    points.append(ParetoPoint(0.5, False, reason=f"no design {ODD}"))
    return ParetoFront(tuple(points), seed=4)


def test_pareto_front():
    front = pareto_front()
    figures = [f"{len(front.points)} levels, {len(front.feasible_points)} feasible, seed 4"]
    figures += [g3(p.worst_deg, "°") for p in front.feasible_points]
    _check(front, figures, odd=front.points[-1].reason)
    many = pareto_front(40)
    text = _check(many, [f"{40 - 15} more levels"])
    shown, hidden = many.points[14], many.points[15]
    assert f"margin ≥ {g3(shown.required_margin_mm, 'mm')}:" in text
    assert f"margin ≥ {g3(hidden.required_margin_mm, 'mm')}:" not in text


def test_drift_front():
    from reflector_opt.optimiser._drift_front import DriftFront, DriftPoint

    kept = DriftPoint(None, True, drift_deg=0.2, objective_deg=0.1)
    dominated = DriftPoint(0.1, True, drift_deg=0.3, objective_deg=0.2, dominated=True)
    front = DriftFront((kept, dominated, DriftPoint(0.05, False, reason=f"no design {ODD}")), 7)
    _check(front, ["3 levels, 1 on the front, seed 7"], odd=front.points[-1].reason)


@pytest.fixture(scope="module")
def part():
    return get_part("EE-SY193")


def test_sensor_choice(part):
    ranking = [
        {"rank": k + 1, "part": f"P{k}", "status": "ranked", "objective_deg": 0.2 + 0.1 * k}
        for k in range(12)
    ]
    ranking.append({"rank": None, "part": "Q", "status": "skipped", "reason": ODD})
    result = SimpleNamespace(objective=0.2345)
    choice = SensorChoice(result, part, {"chosen": part.name, "ranking": ranking[-1:] + ranking})
    figures = [part.name, part.maker, g3(0.2345, "°"), g3(ranking[3]["objective_deg"], "°")]
    _check(choice, figures, odd=ODD)


def plan_study():
    predictions = [
        PlanPrediction(pattern, n, form, np.array([0.3, 0.2]) * (1 + n / 100), np.ones(2), (), 90)
        for pattern in ("grid", "spiral")
        for n in (9, 25)
        for form in ("poly3", "physical")
    ]
    return PlanStudy(predictions, np.array([0.11, 0.07]), n_units=6, seed=2)


def test_plan_study():
    study = plan_study()
    floor = study.floor_rms_deg
    figures = [f"{len(study.predictions)} predictions on 6 units", g3(floor[0], "°")]
    for p in study.predictions:
        figures += [g3(p.rms_deg[0], "°"), g3(p.rms_deg[1] / floor[1])]
    _check(study, figures)


def test_identification_study():
    count = PoseCount(0.5, 24, {"radius_mm": 24}, np.ones(3), np.arange(24))
    plan = PatternRow("chosen", 24, 12.3456, np.ones(3), np.zeros((24, 2)))
    study = IdentificationStudy(None, count, plan, [plan] * 5, [], plan_study(), 6, 1, "built", 3.0)
    figures = ["6 units (built truth)", "chosen, 24 poses", g3(plan.log_det), "8 predictions"]
    _check(study, figures)
    none = IdentificationStudy(None, count, None, [], [], None, 6, 1, "model", 3.0)
    _check(none, ["none reaches the target"])


def batch_mean():
    directions = tuple(
        Direction(f"direction {k} {ODD}", np.ones(3), 0.5 - k, 0.25 + k, 0.4) for k in range(3)
    )
    batch = SimpleNamespace(n_units=5)
    return BatchMean(batch, directions, (), np.zeros(3), np.ones(3), 1.23, True, False)


def test_batch_mean():
    m = batch_mean()
    figures = ["5 units, 3 determined directions", g3(m.scatter_factor)]
    figures += [f"{g3(d.estimate)} ± {g3(d.std)}" for d in m.directions]
    _check(m, figures, odd=m.directions[0].name)


def test_correction():
    c = Correction(batch_mean(), (True, False, True), 9.87, 7.81, 2.0, 0.95, (True,) * 3, 1.0)
    figures = ["2 of 3 directions corrected", g3(c.chi2), g3(c.threshold), f"{c.dof} dof"]
    assert "significant: yes" in _check(c, figures, odd=ODD)


def test_as_built_model(design):
    model = AsBuiltModel(design, Mismatch((1.01, 0.98), (0.012, -0.03)))
    figures = [f"{design.reflector.radius_mm:.3f} mm", "(1.0100, 0.9800)", "(0.0120, -0.0300) V"]
    _check(model, figures + [s.name for s in design.sensors])


def test_curve_fit(part):
    fit = CurveFit(part.model, 0.0123, 0.0456)
    figures = [part.model.name, g3(0.0123, "V"), g3(0.0456, "V")]
    _check(fit, [*figures, g3(part.model.source_radius_mm, "mm")])


def test_material_fit():
    fit = MaterialFit(
        reflectance=0.812,
        specular_fraction=0.345,
        reflectance_sigma=0.021,
        specular_fraction_sigma=0.033,
        correlation=-0.4,
        reflectance_model_form_sigma=0.04,
        specular_fraction_model_form_sigma=0.05,
        reflectance_interval=(0.74, 0.88),
        specular_fraction_interval=(0.25, 0.44),
        subsurface_mm=None,
        subsurface_interval_mm=None,
        offset_v=-0.07,
        rms_residual_v=0.011,
        max_residual_v=0.029,
        points=41,
        clamped=3,
        sigma_v=0.002,
        misfit=False,
        reference_rms_v=None,
        sensor=None,
    )
    figures = ["0.812 ± 0.021", "0.345 ± 0.033", g3(-0.4), "41 (3 clamped left out)"]
    _check(fit, [*figures, "not determined", g3(0.74) + "–" + g3(0.88)])


def test_fit_result(part):
    fit = fit_part(part.figures, part.model)
    worst = max(fit.residuals, key=lambda k: abs(fit.residuals[k]))
    figures = [f"{worst}: {g3(fit.residuals[worst])}"]
    figures += [g3(getattr(fit.model, name)) for name in fit.fitted]
    _check(fit, figures)


def test_catalogue_part(part):
    across, along, depth = part.package_mm
    figures = [f"{part.name} ({part.maker})", f"{across:.3g} × {along:.3g} × {depth:.3g} mm"]
    _check(part, [*figures, part.origin])


def test_clearance_proof():
    proof = ClearanceProof(120, 4, 3000, None, 0.4321, (12.0, -3.0), 0.25, 0.8)
    figures = ["120 / 4", g3(0.4321, "mm") + " at pitch 12°, roll -3°", g3(0.25, "mm")]
    assert "contact: none" in _check(proof, figures)
    assert proof == ClearanceProof(120, 4, 3000, None, 0.4321, (12.0, -3.0), 0.25, 0.8)


def test_printability_report():
    report = PrintabilityReport(
        ODD,
        True,
        True,
        False,
        1234.5,
        [[-1, -2, 0], [1, 2, 3]],
        True,
        0.8,
        "shell",
        0.9,
        0.95,
        None,
        ("winding is not consistent",),
    )
    figures = ["1 problems", g3(1234.5, "mm³"), "(-1.00, -2.00, 0.00) to (1.00, 2.00, 3.00) mm"]
    _check(report, [*figures, "winding is not consistent", "shell: 0.9 mm"], odd=ODD)
