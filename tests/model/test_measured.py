"""Sensor models from a measured flat-target curve: reading, fitting, interpolating."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.model._exact import exact_coupling
from reflector_opt.model._exact_model_form import exact_model_form_coupling
from reflector_opt.model._forward import respond
from reflector_opt.model._measured import fit_sensor_model, read_curve_csv
from reflector_opt.model._optics import surface_couplings
from reflector_opt.model._sensors import NJL5901R_2, SensorModel
from reflector_opt.util._errors import InputError

TRUE = NJL5901R_2.with_(source_radius_mm=0.2, divergence_deg=27.0, current_gain=3.0)
DISTANCE = np.linspace(0.3, 3.5, 25)


def _measured(noise_v=0.0, seed=0):
    volts = TRUE.output_voltage(TRUE.flat_coupling(DISTANCE, 0.9))
    return volts + np.random.default_rng(seed).normal(0.0, noise_v, DISTANCE.size)


def test_fit_recovers_the_parameters_of_a_noise_free_curve():
    fit = fit_sensor_model(DISTANCE, _measured(), NJL5901R_2)
    for key in ("source_radius_mm", "divergence_deg", "current_gain"):
        assert_allclose(getattr(fit.model, key), getattr(TRUE, key), rtol=1e-4)
    assert fit.rms_residual_v < 1e-6


def test_fit_against_a_white_diffuse_standard():
    """A Lambertian reference (f = 0) fixes the same parameters, and the curve keeps its f."""
    d = DISTANCE[::2]
    volts = TRUE.output_voltage(TRUE.flat_coupling(d, 0.99, 0.0))
    fit = fit_sensor_model(d, volts, NJL5901R_2, reflectance=0.99, specular_fraction=0.0)
    for key in ("source_radius_mm", "divergence_deg", "current_gain"):
        assert_allclose(getattr(fit.model, key), getattr(TRUE, key), rtol=1e-4)
    curve = fit_sensor_model(
        d, volts, NJL5901R_2, method="interpolate", reflectance=0.99, specular_fraction=0.0
    ).model.measured_curve
    assert (curve.reflectance, curve.specular_fraction) == (0.99, 0.0)


def test_flat_curve_hardly_fixes_the_emitter_detector_spacing():
    """Scaling e, ω0 and tan θ by k and the gain by k² gives nearly the same flat-target
    curve over the usable range (exactly the same in the paraxial limit), which is why the
    fit keeps e from the base model."""
    k = 1.3
    slope = np.tan(np.deg2rad(TRUE.divergence_deg))
    scaled = TRUE.with_(
        emitter_detector_mm=k * TRUE.emitter_detector_mm,
        source_radius_mm=k * TRUE.source_radius_mm,
        divergence_deg=np.rad2deg(np.arctan(k * slope)),
        current_gain=k**2 * TRUE.current_gain,
    )
    usable = DISTANCE >= TRUE.range_mm[0]
    assert_allclose(
        scaled.output_voltage(scaled.flat_coupling(DISTANCE, 0.9))[usable],
        _measured()[usable],
        rtol=0.04,
    )


def test_fit_of_a_noisy_curve_leaves_noise_sized_residuals():
    fit = fit_sensor_model(DISTANCE, _measured(noise_v=0.002), NJL5901R_2)
    assert 0.001 < fit.rms_residual_v < 0.003
    fitted = fit.model.output_voltage(fit.model.flat_coupling(DISTANCE, 0.9))
    clean = _measured()
    assert np.max(np.abs(fitted - clean)) < 0.004  # closer to the truth than the noise


def test_interpolation_reproduces_the_points_and_is_monotonic():
    volts = _measured(noise_v=0.002)
    model = fit_sensor_model(DISTANCE, volts, NJL5901R_2, method="interpolate").model
    flat = model.flat_coupling(DISTANCE, 0.9) * model.flat_correction(DISTANCE)
    unclamped = volts > NJL5901R_2.saturation_v + 0.01  # at saturation the output is clamped
    assert_allclose(model.output_voltage(flat)[unclamped], volts[unclamped], atol=1e-12)
    fine = np.linspace(0.6, 3.5, 2000)  # past the peak the measurement rises monotonically
    between = model.output_voltage(model.flat_coupling(fine, 0.9) * model.flat_correction(fine))
    assert np.all(np.diff(between) > 0)
    assert SensorModel.from_dict(model.to_dict()) == model


def test_forward_model_uses_the_measured_curve(design):
    model = fit_sensor_model(DISTANCE, _measured(), NJL5901R_2, method="interpolate").model
    measured_design = design.with_sensor_model(model)
    plain_design = design.with_sensor_model(model.with_(measured_curve=None))
    pitch, roll = design.workspace.grid(3.0)
    # on a noise-free curve of the model's own family the correction is 1 up to the fit
    assert_allclose(
        respond(measured_design, pitch, roll).volts,
        respond(plain_design, pitch, roll).volts,
        atol=1e-6,
    )


def _write(tmp_path, text):
    path = tmp_path / "curve.csv"
    path.write_text(text)
    return path


def test_read_curve_csv_sorts_and_ignores_extra_columns(tmp_path):
    path = _write(tmp_path, "note,volts,distance_mm\na,2.0,2\nb,1.0,1\nc,3.0,3\nd,3.1,4,,\n")
    d, v = read_curve_csv(path)
    assert_allclose(d, [1, 2, 3, 4])
    assert_allclose(v, [1.0, 2.0, 3.0, 3.1])


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("distance,volts\n1,2\n", r"missing column\(s\) distance_mm"),
        ("distance_mm,volts\n1,2\n2,abc\n3,3\n4,4\n", "row 3: expected numbers"),
        ("distance_mm,volts\n1,2\n2,nan\n3,3\n4,4\n", "row 3: values must be finite"),
        ("distance_mm,volts\n1,2\n2,3\n", "at least 4 rows"),
        ("distance_mm,volts\n1,2\n1,3\n3,3\n4,1\n", "only once"),
        ("", "empty file"),
        # a distance of 1e308 mm was fitted and written; a voltage of 1e308 V ended in a
        # fit that did not converge and a dozen lines of warnings
        (
            "distance_mm,volts\n1,2\n1e308,3\n3,3\n4,4\n",
            r"row 3: distance_mm: expected a number from -1000 to 1000 mm, got 1e308$",
        ),
        (
            "distance_mm,volts\n1,2\n2,-1e308\n3,3\n4,4\n",
            r"row 3: volts: expected a number from -1000 to 1000 V, got -1e308$",
        ),
        # a stray comma shifts the cells after it
        ("distance_mm,volts\n1,2\n2,3,5\n3,3\n4,4\n", "row 3: 3 cells, the header has 2"),
    ],
)
def test_malformed_curves_are_rejected(tmp_path, text, message):
    with pytest.raises(InputError, match=message):
        read_curve_csv(_write(tmp_path, text))


def test_a_sensor_whose_axis_misses_reads_only_the_beam_edge(design):
    """Where the axis misses the reflector only the edge of the beam returns; no NaN."""
    from reflector_opt.design import SensorPlacement

    model = fit_sensor_model(DISTANCE, _measured(), NJL5901R_2, method="interpolate").model
    high = SensorPlacement("S1", model.name, (10.0, 0.0, 8.0), (-1.0, 0.0, 0.0))
    missing = design.with_sensor_model(model).replace(sensors=(high, design.sensors[1]))
    response = respond(missing, 0.0, 0.0)
    assert np.isnan(response.axial_distance_mm[0])  # 9.5 mm off the axis, r_s = 9 mm
    assert 0.0 <= response.coupling[0] < 0.05 * response.coupling[1]
    assert response.volts[0] == model.output_voltage(response.coupling[0])


@pytest.mark.parametrize(
    ("volts", "message"),
    [
        (np.full(DISTANCE.size, NJL5901R_2.supply_v), "every reading is clamped"),
        (np.zeros(DISTANCE.size), "every reading is clamped"),
        (np.full(DISTANCE.size, NJL5901R_2.saturation_v), "every reading is clamped"),
        (np.full(DISTANCE.size, 2.0), r"does not change with the distance \(its readings "),
        (np.r_[np.full(DISTANCE.size - 3, 3.3), 2.0, 2.5, 3.0], r"at least 4 readings.*found 3"),
    ],
    ids=["supply", "zero", "saturation", "constant", "three-points"],
)
def test_a_curve_without_signal_is_refused(volts, message):
    """Each was fitted (a gain of 5 to a curve of zeros) and written as a sensor."""
    with pytest.raises(InputError, match=f"^measured curve: .*{message}"):
        fit_sensor_model(DISTANCE, volts, NJL5901R_2)


def test_a_sensor_carrying_a_curve_without_signal_is_refused():
    """Its correction had no point to interpolate: an internal error on the first use."""
    from reflector_opt.model._flat_target import MeasuredCurve

    flat = MeasuredCurve((0.5, 1.0, 2.0, 3.0), (3.3, 3.3, 3.3, 3.3))
    with pytest.raises(InputError, match=r"^sensor 'X': measured_curve: every reading is clamped"):
        NJL5901R_2.with_(name="X", measured_curve=flat)
    one = MeasuredCurve((0.5, 1.0, 2.0, 3.0), (3.3, 3.3, 2.0, 3.3))
    with pytest.raises(InputError, match=r"needs at least 2 readings .* found 1"):
        NJL5901R_2.with_(name="X", measured_curve=one)
    two = MeasuredCurve((0.5, 1.0, 2.0, 3.0), (3.3, 1.5, 2.0, 3.3))
    assert NJL5901R_2.with_(measured_curve=two).flat_correction(1.5) > 0


# --- fits to curves the fitted model did not make ---------------------------------------------

#: The exact reference's quadrature orders for the lab curves (within 1e-4 of its defaults).
ORDERS = {"source_order": 4, "detector_order": (2, 6), "sphere_order": (64, 64)}
LAB_DISTANCE = np.linspace(0.5, 3.0, 11)


def _exact_flat_volts(distance, **model_form):
    """The true sensor over a flat mirror of reflectance 0.9, by the exact reference (with the
    given physics the fast model leaves out, ``exact_model_form``), through its electronics."""
    coupling = [
        exact_model_form_coupling(
            [0, 0, 0],
            [1, 0, 0],
            [0, 0, TRUE.emitter_detector_mm],
            [d + 1e5, 0, 0],
            1e5,
            TRUE,
            **ORDERS,
            **model_form,
        ).mirror
        for d in distance
    ]
    return TRUE.output_voltage(0.9 * np.array(coupling))


def test_a_fit_to_an_exact_reference_curve_recovers_the_sensor_and_predicts_a_sphere():
    fit = fit_sensor_model(LAB_DISTANCE, _exact_flat_volts(LAB_DISTANCE), NJL5901R_2)
    for key in ("source_radius_mm", "divergence_deg", "current_gain"):
        assert_allclose(getattr(fit.model, key), getattr(TRUE, key), rtol=1e-3)
    # a convex mirror of radius 9 mm, 1 mm away on the axis: the fitted sensor's fast
    # coupling against the true sensor's exact one
    fast = surface_couplings(np.array([[[10.0, 0.0, 0.0]]]), 9.0, 1.0, [fit.model]).mirror
    exact = exact_coupling([0, 0, 0], [1, 0, 0], [0, 0, 0.5], [10.0, 0, 0], 9.0, TRUE, **ORDERS)
    assert fast[0, 0] == pytest.approx(exact.mirror, rel=3e-3)


def test_a_fit_to_a_beam_of_another_shape_reports_its_misfit_and_holds_between_the_points():
    """The LED's pattern a cosine power (docs/model.md §9) instead of the model's Gaussian: the
    fit cannot reproduce the curve exactly; it says so by its residual (0.1 mV), and it
    predicts the curve between the measured distances that read a signal to 1 mV (below the
    first of them, where the clamp hides the curve, it is 7 mV off at 0.625 mm)."""
    shape = {"emitter_pattern": "cosine_power"}
    volts = _exact_flat_volts(LAB_DISTANCE, **shape)
    fit = fit_sensor_model(LAB_DISTANCE, volts, NJL5901R_2)
    modelled = fit.model.output_voltage(fit.model.flat_coupling(LAB_DISTANCE, 0.9))
    misfit = np.sqrt(np.mean((modelled - volts) ** 2))
    assert fit.rms_residual_v == pytest.approx(misfit, rel=1e-6)
    assert 2e-5 < misfit < 1e-3  # not the model's own curve, and still close
    unclamped = LAB_DISTANCE[volts > TRUE.saturation_v]  # 0.5 mm reads the clamp
    between = 0.5 * (unclamped[1:] + unclamped[:-1])
    held_out = fit.model.output_voltage(fit.model.flat_coupling(between, 0.9))
    # within 1 mV, a 12-bit step of 3.3 V (measured 0.52 mV, on the steep side at 0.875 mm)
    assert np.max(np.abs(held_out - _exact_flat_volts(between, **shape))) < 1e-3


def test_a_fitted_offset_takes_up_a_read_out_gain_on_the_output():
    """An exact-reference mirror curve read out as g·V + o (the tolerance model's mismatch):
    that is a collector-current gain g·G and an offset o − (1 − g)·Vcc, which the fit with
    ``fit_offset`` recovers; without it the beam bends to make up the offset."""
    g, o = 0.97, 0.01
    volts = g * _exact_flat_volts(LAB_DISTANCE) + o
    fit = fit_sensor_model(LAB_DISTANCE, volts, NJL5901R_2, fit_offset=True)
    assert fit.offset_v == pytest.approx(o - (1 - g) * TRUE.supply_v, abs=5e-4)
    assert fit.model.current_gain == pytest.approx(g * TRUE.current_gain, rel=3e-3)
    assert fit.model.source_radius_mm == pytest.approx(TRUE.source_radius_mm, rel=3e-3)
    plain = fit_sensor_model(LAB_DISTANCE, volts, NJL5901R_2)
    assert plain.offset_v == 0.0
    assert abs(plain.model.source_radius_mm / TRUE.source_radius_mm - 1) > 0.02
    assert plain.rms_residual_v > 10 * fit.rms_residual_v
