"""The identification's residuals and Jacobian (asbuilt.problem), on a unit made by the
identification's own model and recorded without noise through an exact reference."""

import numpy as np
import pytest

from reflector_opt.asbuilt._modelunit import ModelUnit
from reflector_opt.asbuilt._parameters import ParameterLayout
from reflector_opt.asbuilt._problem import IdentificationProblem, UnitData
from reflector_opt.calibration._plans import make_plan
from reflector_opt.util._errors import InputError


@pytest.fixture(scope="module")
def setting(design):
    layout = ParameterLayout(design, 1)
    unit = ModelUnit.draw(layout, 0, seed=2)
    poses = make_plan(design.workspace, "grid", 9)
    data = UnitData("1", unit.volts(poses[:, 0], poses[:, 1]), poses)
    return layout, unit, data, IdentificationProblem(layout, [data], reference_sigma_deg=0.0)


def test_the_units_own_parameters_leave_no_misfit(setting):
    layout, unit, data, problem = setting
    assert problem.n_data == 9 * 2
    assert np.abs(problem.misfit_v(unit.x, 0)).max() < 1e-9
    # At the nominal parameters the misfit is the nominal unit's voltages less the data.
    nominal = ModelUnit(*layout.unit_design(np.zeros(layout.size), 0, problem.working), 0, None)
    expected = nominal.volts(data.angles_deg[:, 0], data.angles_deg[:, 1]) - data.volts
    np.testing.assert_allclose(problem.misfit_v(np.zeros(layout.size), 0), expected, atol=1e-12)
    # An exact reference: each voltage weighed by the read-out's σ alone.
    x = 0.5 * unit.x
    np.testing.assert_allclose(
        problem.calibration_residuals(x, 0) * problem.sigma_v, problem.misfit_v(x, 0).ravel()
    )


def test_the_prior_residuals_and_their_jacobian_rows(setting):
    layout, unit, _, problem = setting
    free = problem.free
    np.testing.assert_allclose(
        problem.prior_residuals(unit.x), unit.x[free] / problem.prior_std[free]
    )
    residuals = problem.residuals(unit.x)
    assert residuals.shape == (problem.n_data + free.sum(),)
    jacobian = problem.jacobian(unit.x, data_jacobian=np.zeros((problem.n_data, layout.size)))
    np.testing.assert_allclose(
        jacobian[problem.n_data :][:, free], np.diag(1 / problem.prior_std[free])
    )


def test_the_data_jacobian_against_differences_of_the_residuals(setting):
    layout, unit, _, problem = setting
    jacobian = problem.data_jacobian(unit.x)
    assert jacobian.shape == (problem.n_data, layout.size)
    # Independent central differences of every free column, a thousandth of its prior std.
    for j in np.flatnonzero(problem.free):
        step = np.zeros(layout.size)
        step[j] = 1e-3 * problem.prior_std[j]
        difference = (
            problem.data_residuals(unit.x + step) - problem.data_residuals(unit.x - step)
        ) / (2 * step[j])
        np.testing.assert_allclose(
            jacobian[:, j], difference, rtol=2e-2, atol=1e-3 * np.abs(difference).max()
        )


def test_a_unit_with_too_few_samples_is_refused(setting):
    layout, _, data, _ = setting
    short = UnitData("7", data.volts[:2], data.angles_deg[:2])
    with pytest.raises(InputError, match=r"^unit 7: 2 samples give 4 voltages, fewer than the \d+"):
        IdentificationProblem(layout, [short], reference_sigma_deg=0.0).check_counts()
