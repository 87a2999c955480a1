"""The systematic term of physics the model lacks."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.asbuilt.modelform import (
    EXACT,
    OPTICAL_EFFECTS,
    reference_units,
    shifts,
    systematic_covariance,
)
from reflector_opt.asbuilt.parameters import Layout
from reflector_opt.asbuilt.problem import Curve, UnitData
from reflector_opt.tolerance.formerror import FormError


def test_the_shifts_are_the_exact_reference_and_each_effect_beyond_it():
    base, first, second = np.array([1.0, 2.0]), np.array([1.5, 2.0]), np.array([0.0, 0.0])
    found = shifts([base, first, second])
    assert_allclose(found, [[1.0, 2.0], [0.5, 0.0], [-1.0, -2.0]])


def test_the_systematic_term_is_the_same_in_every_unit_and_correlated_between_them(design):
    layout = Layout(design, 3)
    one = np.arange(len(layout.unit_indices(0)), dtype=float)
    cov = systematic_covariance([one], layout)
    for u in range(3):
        index = layout.unit_indices(u)
        assert_allclose(cov[np.ix_(index, index)], np.outer(one, one))
    a, b = layout.unit_slice(0), layout.unit_slice(2)
    assert_allclose(cov[a, b], cov[a, a])  # fully correlated: it does not average out
    assert np.linalg.matrix_rank(cov) == 1


def test_reference_units_are_the_nominal_unit_on_the_batch_plan(design):
    poses = np.array([[0.0, 0.0], [10.0, -5.0], [-12.0, 8.0]])
    distance = np.array([0.6, 1.0, 2.0])
    template = UnitData("t", np.zeros((3, 2)), poses, (Curve(1, distance, distance),))
    found = reference_units(design, template, FormError().only("emitter_pattern"))
    assert [name for name, _ in found] == [EXACT, "emitter_pattern"]
    exact, pattern = (data for _, data in found)
    assert_allclose(exact.angles_deg, poses)
    assert exact.curves[0].sensor == 1 and exact.curves[0].volts.shape == (3,)
    # a cosine-power emitter of the same 1/e width puts more light on the axis: lower volts
    assert np.all(pattern.volts < exact.volts)
    assert "specular_roughness_deg" in OPTICAL_EFFECTS


def test_crosstalk_and_ambient_alone_add_no_reference_unit(design):
    template = UnitData("t", np.zeros((1, 2)), np.zeros((1, 2)))
    found = reference_units(design, template, FormError().only("crosstalk_coupling"))
    assert [name for name, _ in found] == [EXACT]


@pytest.mark.parametrize("model_form", [None, FormError()])
def test_identify_records_the_systematic_part_of_the_covariance(design, model_form):
    from reflector_opt.asbuilt.identification import identify
    from reflector_opt.tolerance.truth import build_unit, built_unit_protocol

    unit = build_unit(design, 0, seed=4)
    poses = np.stack(np.meshgrid(np.linspace(-15, 15, 8), np.linspace(-15, 15, 8)), -1)
    calibration = built_unit_protocol(unit, poses.reshape(-1, 2), n_validation=1).calibration
    found = identify(
        design,
        {"1": (calibration.volts, calibration.angles_deg)},
        profiles=False,
        model_form=model_form,
    )
    systematic = np.diag(found.systematic_covariance)
    if model_form is None:
        assert np.all(systematic == 0)
    else:
        assert systematic.max() > 0
        assert np.all(np.diag(found.covariance) >= systematic)
        row = found.unit_parameters(0)["reflector_centre_z_mm"]
        assert row["model_form_std"] == pytest.approx(np.sqrt(systematic[2 + 3]))
