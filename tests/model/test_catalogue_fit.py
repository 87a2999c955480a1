"""Fitting a catalogue part's model to its datasheet figures (model.catalogue_fit): the flat
curve's peak and levels, the figures a model predicts, the matched load and the fit."""

import numpy as np
import pytest

from reflector_opt.model._catalogue import shipped_catalogue
from reflector_opt.model._catalogue_fit import (
    fit_part,
    flat_peak,
    level_distances,
    matched_load_ohm,
    predicted_figures,
)
from reflector_opt.model._optics import flat_target_coupling
from reflector_opt.model._sensors import NJL5901R_2

PARTS = {p.name: p for p in shipped_catalogue()}


def test_flat_peak_is_the_top_of_a_dense_scan():
    # Independent path: a linear scan of the white card's coupling (ρ 0.9, f 0), 400 points
    # to 5 mm, then 401 between the best point's neighbours (steps of 63 µm, then 0.3 µm).
    coarse = np.linspace(0.01, 5.0, 400)
    i = int(np.argmax(flat_target_coupling(coarse, NJL5901R_2, 0.9, 0.0)))
    d = np.linspace(coarse[i - 1], coarse[i + 1], 401)
    eta = flat_target_coupling(d, NJL5901R_2, 0.9, 0.0)
    distance, coupling = flat_peak(NJL5901R_2, "white-card")
    # flat_peak's golden-section search stops within 1 µm; the curve is flat at its top.
    assert distance == pytest.approx(d[np.argmax(eta)], abs=2e-3)
    assert coupling == pytest.approx(eta.max(), rel=1e-6)


def test_level_distances_are_where_the_curve_is_that_share_of_its_peak():
    peak = flat_peak(NJL5901R_2, "mirror")
    near, far = level_distances(NJL5901R_2, 0.2, "mirror", peak)
    assert 0.0 < near < peak[0] < far
    eta = flat_target_coupling(np.array([near, far]), NJL5901R_2, 1.0, 1.0)
    np.testing.assert_allclose(eta / peak[1], 0.2, atol=1e-3)


def test_matched_load_scales_inversely_with_the_gain():
    reference = NJL5901R_2
    assert matched_load_ohm(reference, reference) == pytest.approx(reference.load_resistor_ohm)
    # Twice the phototransistor's gain: half the load gives the same swing, G·I_F·η·R2.
    doubled = reference.with_(current_gain=2 * reference.current_gain)
    assert matched_load_ohm(doubled, reference) == pytest.approx(
        reference.load_resistor_ohm / 2, rel=1e-9
    )


def test_predicted_output_current_is_gain_times_led_current_times_coupling():
    part = PARTS["EE-SY193"]
    figures, model = part.figures, part.model
    predicted = predicted_figures(model, figures)
    assert predicted["peak_distance_mm"] == pytest.approx(
        flat_peak(model, figures["test_target"].value)[0]
    )
    if "output_current_a" in figures:
        rho, f = {"white-card": (0.9, 0.0), "aluminium": (0.9, 1.0), "mirror": (1.0, 1.0)}[
            figures["test_target"].value
        ]
        eta = flat_target_coupling(np.array([figures["test_distance_mm"].value]), model, rho, f)[0]
        assert predicted["output_current_a"] == pytest.approx(
            model.current_gain * figures["test_led_current_a"].value * eta, rel=1e-12
        )


def test_a_refit_returns_the_stored_model():
    part = PARTS["EE-SY193"]
    fit = fit_part(part.figures, part.model)
    for key in ("emitter_detector_mm", "source_radius_mm", "divergence_deg", "current_gain"):
        assert getattr(fit.model, key) == pytest.approx(getattr(part.model, key), rel=2e-3)
    assert abs(fit.residuals["peak_distance_mm"]) < 1.0
