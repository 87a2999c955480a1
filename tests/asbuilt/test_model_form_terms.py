"""Physics the fast model lacks: the spread fitted, the bias subtracted, the rest carried."""

from dataclasses import replace

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.asbuilt._model_form_terms import (
    EXACT,
    OPTICAL_EFFECTS,
    effects_of,
    model_form_names,
    model_form_terms,
    reference_units,
)
from reflector_opt.asbuilt._problem import Curve, UnitData
from reflector_opt.model._forward import voltages
from reflector_opt.tolerance._model_form import ModelForm

POSES = np.array([[0.0, 0.0], [10.0, -5.0], [-12.0, 8.0], [15.0, 15.0]])


def test_the_signatures_are_per_sensor_and_the_bias_is_the_exact_reference(design):
    template = UnitData(
        "t", np.zeros((len(POSES), 2)), POSES, (Curve(1, np.array([0.6, 1.5]), np.zeros(2)),)
    )
    terms = model_form_terms(design, [template], ModelForm(), spread_fitted=True)
    names = model_form_names(ModelForm(), 2)
    assert len(names) == 2 * len(effects_of(ModelForm()))
    assert names[0].endswith("_sensor_1") and names[-1].endswith("_sensor_2")
    signatures = terms.signatures[0]
    assert signatures.shape == (len(names), len(POSES), 2)
    half = len(names) // 2
    # sensor 1's terms touch only sensor 1's column: S2 − S1 contrasts are covered
    assert np.all(signatures[:half, :, 1] == 0) and np.all(signatures[half:, :, 0] == 0)
    assert np.abs(signatures[:half, :, 0]).max() > 5e-3  # millivolts: the LED pattern
    # the bias is the exact reference's nominal unit less the fast model
    exact = reference_units(design, template, ModelForm.none())[0][1].volts
    assert_allclose(terms.bias[0], exact - voltages(design, *POSES.T), atol=1e-9)
    # a curve of sensor 2 carries sensor 2's amplitudes only
    curve = terms.curve_signatures[0][0]
    assert np.all(curve[:half] == 0) and np.abs(curve[half:]).max() > 1e-3


def test_reference_units_are_the_nominal_unit_on_the_batch_plan(design):
    distance = np.array([0.6, 1.0, 2.0])
    template = UnitData("t", np.zeros((4, 2)), POSES, (Curve(1, distance, distance),))
    found = reference_units(design, template, ModelForm().only("emitter_pattern"))
    assert [name for name, _ in found] == [EXACT, "emitter_pattern"]
    exact, pattern = (data for _, data in found)
    assert_allclose(exact.angles_deg, POSES)
    assert exact.curves[0].sensor == 1 and exact.curves[0].volts.shape == (3,)
    # a cosine-power emitter of the same 1/e width puts more light on the axis: lower volts
    assert np.all(pattern.volts < exact.volts)
    assert "specular_roughness_deg" in OPTICAL_EFFECTS


def test_crosstalk_and_ambient_alone_add_no_signature(design):
    assert effects_of(ModelForm().only("crosstalk_coupling", "ambient_current_ua")) == []
    assert model_form_names(None, 2) == ()


@pytest.mark.slow
@pytest.mark.parametrize("model_form", [None, ModelForm()])
def test_no_posterior_std_exceeds_its_prior(design, model_form):
    """The model-form amplitudes are fitted with the rest, so their uncertainty is in the
    posterior covariance, which the data can only narrow: every std at most its prior's
    (the share that comes from them recorded), and none without them."""
    from reflector_opt.asbuilt._identification import identify
    from reflector_opt.tolerance._builtunit import build_unit, built_unit_protocol

    unit = build_unit(design, 0, seed=4, model_form=ModelForm())
    poses = np.stack(np.meshgrid(np.linspace(-15, 15, 8), np.linspace(-15, 15, 8)), -1)
    calibration = built_unit_protocol(unit, poses.reshape(-1, 2), n_validation=1).calibration
    found = identify(
        design,
        {"1": (calibration.volts, calibration.angles_deg)},
        profiles=False,
        model_form=model_form,
    )
    prior = found.layout.prior_std()
    assert np.all(found.std <= prior * (1 + 1e-9))
    systematic = np.diag(found.systematic_covariance)
    if model_form is None:
        assert np.all(systematic == 0) and not found.layout.model_form_names
    else:
        assert systematic.max() > 0
        assert np.all(np.diag(found.covariance) >= systematic - 1e-15)
        row = found.unit_parameters(0)["reflector_centre_z_mm"]
        j = found.layout.names().index("unit 1: reflector_centre_z_mm")
        assert row["model_form_std"] == pytest.approx(np.sqrt(systematic[j]))


@pytest.fixture(scope="module")
def spread_unit(design):
    """A built unit whose resin spreads its light 0.2 mm (twice the default), its cosine-power
    LED and the rest of ``ModelForm()``, calibrated on 120 Sobol poses."""
    from reflector_opt.calibration._plans import make_plan
    from reflector_opt.tolerance._builtunit import build_unit, built_unit_protocol

    form = replace(ModelForm(), subsurface_mm=0.2)
    unit = build_unit(design, 0, seed=11, model_form=form, surface=(0.9, 0.05))
    plan = make_plan(design.workspace, "sobol", 120, seed=0)
    calibration = built_unit_protocol(unit, plan, n_validation=1, seed=0).calibration
    return unit, {"u": (calibration.volts, calibration.angles_deg)}


def _centre_z_error(design, unit, result):
    from reflector_opt.asbuilt._parameters import true_deviations

    j = result.layout.names(list(result.labels)).index("unit u: reflector_centre_z_mm")
    truth = true_deviations(design, unit.design, unit.mismatch)[3]
    return (result.x[j] - truth) / result.std[j]


def test_a_spread_twice_the_default_leaves_the_centre_height_covered(design, spread_unit):
    """With the spread fitted and the model form carried, the centre height's 90 % interval
    holds the truth; with both left out, the same data pull it several std off."""
    from reflector_opt.asbuilt._identification import identify

    unit, samples = spread_unit
    found = identify(design, samples, profiles=False, reference_std=None)
    assert abs(_centre_z_error(design, unit, found)) < 1.645
    ell = found.shared_parameters()["subsurface_mm"]
    assert abs(ell["estimate"] - 0.2) < 1.645 * ell["std"]
    plain = identify(
        design, samples, profiles=False, reference_std=None, model_form=None, subsurface_std=None
    )
    assert abs(_centre_z_error(design, unit, plain)) > 2.5


def test_the_model_form_covers_the_contrast_between_the_sensors(design, spread_unit):
    """Part-to-part LED differences land on S2 − S1: the model-form share of the covariance
    along the contrast of the two sensors' beam widths is a sizeable part of its prior (it
    was below 1e-4 with one physics for both sensors), as it is along their sum."""
    from reflector_opt.asbuilt._identification import identify

    _, samples = spread_unit
    found = identify(design, samples, profiles=False, reference_std=None)
    names = found.layout.names(list(found.labels))
    j1, j2 = (names.index(f"unit u: sensor_{k}_divergence_deg") for k in (1, 2))
    prior = found.layout.prior_std()[j1]
    for sign in (-1.0, 1.0):
        w = np.zeros(len(names))
        w[j1], w[j2] = 1.0, sign
        share = w @ found.systematic_covariance @ w / 2.0
        assert share > 0.05 * prior**2
