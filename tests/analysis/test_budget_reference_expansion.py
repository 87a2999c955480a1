"""The budget's angle-reference class and the printed parts' expansion: hand-computed values,
an inversion through the exact reference model, and a calibration against a noisy reference."""

from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import least_squares

from reflector_opt.analysis import _budget as budget
from reflector_opt.analysis._budget import error_budget, expanded_design
from reflector_opt.calibration._models import make_model
from reflector_opt.design import default_design
from reflector_opt.design._conditions import ANGLE_REFERENCES, Conditions
from reflector_opt.design._design import load_design
from reflector_opt.model._reference import direct_response
from tests.analysis.test_budget import _built

SAMPLE = (
    Path(__file__).resolve().parents[2] / "tests" / "data" / "design_6c47a9f.json"
)  # the issue's
#: Nothing but the source under test.
QUIET = Conditions.quiet()
#: The expansion at ±5 K with the default coefficients, every other source at zero.
WARM = QUIET.replace(temperature_range_k=5.0, resin_cte_ppm_per_k=145.1, strip_cte_ppm_per_k=13.0)
#: The budget's grid step of these checks, degrees (7 × 7 poses over ±15°).
STEP = 5.0


# --- the angle reference ---------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kind", "speed", "expected"),
    [
        # the paper's slow sweep: ω²L/g = (5°/s in rad)² · 0.1 m / g = 0.004°, below the class
        ("imu-lpms-b", 5.0, 1.0),
        ("imu-lpms-b", 0.0, 1.0),  # at rest: its static class
        # ω²L/g reaches 1°: ω = sqrt(g · 1° in rad / 0.1 m) = 1.309 rad/s = 75.0°/s
        ("imu-lpms-b", 74.0, 1.0),
        ("imu-lpms-b", 76.0, 3.0),  # its dynamic class (assumed)
        ("imu-lpms-b2", 5.0, 0.5),  # < 0.5° static
        ("imu-lpms-b2", 60.0, 2.0),  # 60°/s reaches its 0.5°: < 2° RMS dynamic
        ("encoder", 200.0, 5.49 / 3600),  # no dynamic class: its static one
    ],
)
def test_the_reference_class_is_the_zero_on_each_angle(kind, speed, expected):
    conditions = QUIET.replace(
        angle_reference=kind, reference_zero_deg=None, angular_speed_deg_s=speed
    )
    assert conditions.reference_zero() == (expected, expected)
    term = error_budget(default_design(), conditions, step_deg=STEP).sources["reference"]
    # no twist: every pose is off by the zero, RMS and max alike
    for value in term.to_dict().values():
        assert value == pytest.approx(expected, rel=1e-12)


def test_a_stated_zero_wins_over_the_class_and_is_not_listed_as_assumed():
    stated = QUIET.replace(angle_reference="imu-lpms-b", reference_zero_deg=[0.2, -0.3])
    term = error_budget(default_design(), stated, step_deg=STEP).sources["reference"]
    assert (term.pitch_rms_deg, term.roll_rms_deg) == pytest.approx((0.2, 0.3), rel=1e-12)
    assert not any("angle reference" in f["figure"] for f in budget_assumed(stated))
    by_class = budget_assumed(QUIET.replace(reference_zero_deg=None, angular_speed_deg_s=5.0))
    (row,) = [f for f in by_class if "angle reference" in f["figure"]]
    figure = ANGLE_REFERENCES["imu-lpms-b"]["static_deg"]
    assert (row["value"], row["range"]) == (figure["value"], figure["range"])
    published = QUIET.replace(angle_reference="imu-lpms-b2", reference_zero_deg=None)
    assert not any("angle reference" in f["figure"] for f in budget_assumed(published))


def budget_assumed(conditions):
    return error_budget(default_design(), conditions, step_deg=STEP).assumed


def test_a_calibration_against_a_biased_noisy_reference_learns_the_bias_and_averages_the_noise():
    """A built unit calibrated (poly5: p = 21 coefficients per angle, N = 169 poses) against
    a reference reading b + ε (σ on each angle) carries b in use, and of ε its fit's
    σ·sqrt(p/N) over the calibration's poses (the hat matrix's trace p over N): within the
    class a = |b| + σ, b² + σ²p/N ≤ a², which all bias reaches (the budget's zero)."""
    unit, calibration, poses = _built(0)
    pitch, roll = np.meshgrid(np.linspace(-15, 15, 13), np.linspace(-15, 15, 13), indexing="ij")
    true = np.column_stack([pitch.ravel(), roll.ravel()])
    bench = unit.volts(true[:, 0], true[:, 1])

    def error(read, volts):
        fitted = make_model("poly5").fit(bench, read)
        return fitted.predict(volts) - calibration.predict(volts)

    bias, sigma = np.array([0.3, -0.3]), 0.2
    in_use = error(true + bias, unit.volts(poses[:, 0], poses[:, 1]))
    assert np.sqrt(np.mean(in_use**2, axis=0)) == pytest.approx(np.abs(bias), rel=0.02)
    rng = np.random.default_rng(3)
    squares = [
        np.mean(error(true + sigma * rng.standard_normal(true.shape), bench) ** 2, axis=0)
        for _ in range(8)
    ]
    assert np.sqrt(np.mean(squares, axis=0)) == pytest.approx(sigma * np.sqrt(21 / 169), rel=0.15)
    # the LPMS-B2's class at rest, 0.5° = |b| + σ here: the budget's zero, above both
    budgeted = error_budget(
        default_design(),
        QUIET.replace(angle_reference="imu-lpms-b2", reference_zero_deg=None),
        step_deg=STEP,
    ).sources["reference"]
    assert budgeted.pitch_rms_deg == pytest.approx(np.abs(bias[0]) + sigma, rel=1e-12)
    assert bias[0] ** 2 + sigma**2 * 21 / 169 < budgeted.pitch_rms_deg**2


# --- the printed parts' expansion ------------------------------------------------------------


def test_the_expanded_geometry_by_hand():
    design = load_design(SAMPLE)
    strain = 30e-6 * 5.0  # the 30 ppm/K over 5 K
    grown = expanded_design(design, strain, 13e-6 * 5.0)
    radius = design.reflector.radius_mm
    assert (grown.reflector.radius_mm - radius) * 1e3 == pytest.approx(8.500043 * 0.15, rel=1e-6)
    assert grown.reflector.centre_mm == pytest.approx(
        np.multiply(design.reflector.centre_mm, 1 + strain), rel=1e-14
    )
    assert grown.positions_mm == pytest.approx(design.positions_mm * (1 + 65e-6), rel=1e-14)
    assert grown.axes == pytest.approx(design.axes, rel=1e-14)


def _inverted(design, grown, pitch, roll):
    """The pose the nominal design reads from ``grown``'s outputs, by least squares through
    the exact reference model (no code of forward.voltages or the Jacobian), degrees."""
    found = []
    for p, r in zip(pitch, roll, strict=True):
        target = direct_response(grown, p, r)[2]

        def misfit(x, target=target):
            return direct_response(design, x[0], x[1])[2] - target

        found.append(least_squares(misfit, [p, r], x_scale=1.0, xtol=1e-12, ftol=1e-15).x)
    return np.array(found) - np.column_stack([pitch, roll])


def _truth(design, conditions):
    """The exact inversion's errors at the budget's grid, both scenarios (+ΔT, −ΔT)."""
    pitch, roll = np.meshgrid(*design.workspace.axes(STEP), indexing="ij")
    dt = conditions.temperature_range_k
    return np.stack(
        [
            _inverted(
                design,
                expanded_design(
                    design,
                    1e-6 * conditions.resin_cte_ppm_per_k * t,
                    1e-6 * conditions.strip_cte_ppm_per_k * t,
                ),
                pitch.ravel(),
                roll.ravel(),
            )
            for t in (dt, -dt)
        ]
    )


@pytest.mark.parametrize(
    "coefficients", [(145.1, 13.0), (30.0, 0.0)], ids=["defaults", "the issue's 30 ppm/K"]
)
def test_the_expansion_matches_an_exact_inversion(coefficients):
    design = load_design(SAMPLE)
    resin, strip = coefficients
    conditions = WARM.replace(resin_cte_ppm_per_k=resin, strip_cte_ppm_per_k=strip)
    ours = error_budget(design, conditions, step_deg=STEP).scenarios["expansion"]
    truth = _truth(design, conditions)
    scale = np.abs(truth).max()
    assert scale > 0.05  # a tenth of a degree or so: a real term
    # signed, pose by pose: the linearisation through J against the exact inversion
    assert np.abs(ours - truth).max() < 0.05 * scale


def test_the_comparison_fails_when_the_term_is_wrong(monkeypatch):
    design = load_design(SAMPLE)
    truth = _truth(design, WARM)
    for factor in (2.0, -1.0):  # doubled, wrong-signed

        def wrong(d, a, b, *, workspace=None, factor=factor):
            return expanded_design(d, factor * a, factor * b, workspace=workspace)

        monkeypatch.setattr(budget, "expanded_design", wrong)
        ours = error_budget(design, WARM, step_deg=STEP).scenarios["expansion"]
        assert np.abs(ours - truth).max() > 0.5 * np.abs(truth).max()


def test_a_compensation_leaves_the_expansion_of_the_thermometer_error():
    """Linear in ΔT, the expansion is learned by a compensation fitted on temperature but for
    the thermometer's error e = 0.5 K + 30 s · 0.5 K/min = 0.75 K (the defaults)."""
    design = default_design()
    compensated = error_budget(
        design, Conditions().replace(temperature_range_k=5.0, temperature_compensated=True)
    ).sources["expansion"]
    at_e = error_budget(design, Conditions().replace(temperature_range_k=0.75)).sources["expansion"]
    assert compensated.to_dict() == pytest.approx(at_e.to_dict(), rel=1e-12)
    assert compensated.pitch_rms_deg > 0.0
