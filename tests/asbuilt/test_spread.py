"""Light spread under the reflector's surface in the fast model (asbuilt.spread): none is the
fast model, the exact sphere's spread followed, the flat curve's closed form."""

from dataclasses import replace

import numpy as np
from numpy.testing import assert_allclose

from reflector_opt.asbuilt._spread import spread_curve_volts, spread_voltages
from reflector_opt.model._exact_model_form import exact_model_form_design_coupling
from reflector_opt.model._flat_hankel import flat_couplings
from reflector_opt.model._forward import respond, voltages
from reflector_opt.tolerance._builtunit import EXACT_ORDERS

POSES = np.array([[0.0, 0.0], [10.0, -5.0], [-12.0, 8.0], [15.0, 15.0]])


def test_no_spread_is_the_fast_model(design):
    assert_allclose(
        spread_voltages(design, POSES[:, 0], POSES[:, 1], None), voltages(design, *POSES.T)
    )


def test_the_spread_follows_the_exact_sphere_closely(design):
    """The flat-target ratio at the Eq 3 distance against the exact reference's spread on
    the sphere: the diffuse part's change within a fifth of itself (the rest is carried)."""
    pitch, roll = POSES[:, 0], POSES[:, 1]
    exact = exact_model_form_design_coupling(design, pitch, roll, subsurface_mm=0.2, **EXACT_ORDERS)
    plain = exact_model_form_design_coupling(design, pitch, roll, **EXACT_ORDERS)
    exact_change = exact.lambertian / plain.lambertian - 1.0
    opaque = replace(design.reflector, specular_fraction=0.0, reflectance=1.0)
    diffuse = design.replace(reflector=opaque)
    model = respond(diffuse, pitch, roll).coupling
    fast = np.stack(
        [
            [m.coupling_from_voltage(v) for v in col]
            for m, col in zip(
                diffuse.models, spread_voltages(diffuse, pitch, roll, 0.2).T, strict=True
            )
        ],
        axis=-1,
    )
    fast_change = fast / model - 1.0
    assert np.all(exact_change < -0.05)  # the spread takes light from where it is seen
    assert np.all(np.abs(fast_change - exact_change) < 0.2 * np.abs(exact_change))


def test_the_flat_curve_spread_is_the_closed_form(design):
    model = design.models[0]
    d = np.array([0.5, 1.0, 2.0])
    parts = flat_couplings(d, model, subsurface_mm=0.15)
    closed = model.output_voltage(parts.total(0.9, 0.0))
    assert_allclose(spread_curve_volts(model, d, 0.9, 0.0, 0.15), closed, atol=2e-3)
