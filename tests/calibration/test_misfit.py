"""The calibration form's own error on a design's noise-free voltages (calibration.misfit)."""

import numpy as np
import pytest

from reflector_opt.calibration._misfit import form_misfit_deg
from reflector_opt.design import default_design
from reflector_opt.model._forward import voltages
from reflector_opt.util._errors import InputError

DESIGN = default_design()
PITCH, ROLL = (a.ravel() for a in np.meshgrid(np.linspace(-20, 20, 5), np.linspace(-20, 20, 5)))


def test_misfit_is_the_least_squares_residual_of_the_form():
    # Independent path: poly1 is a plane a + b·v1 + c·v2 per angle; its least-squares fit by
    # numpy's lstsq, estimated minus true.
    volts = voltages(DESIGN, PITCH, ROLL)
    matrix = np.column_stack([np.ones(len(PITCH)), volts])
    angles = np.column_stack([PITCH, ROLL])
    coef, *_ = np.linalg.lstsq(matrix, angles, rcond=None)
    misfit = form_misfit_deg(DESIGN, PITCH, ROLL, form="poly1")
    assert misfit.shape == (25, 2)
    np.testing.assert_allclose(misfit, matrix @ coef - angles, atol=1e-8)
    assert np.abs(misfit).max() > 0.1  # a plane cannot follow the response: a real misfit
    # Least squares with a constant term: the residuals sum to zero per angle.
    np.testing.assert_allclose(misfit.sum(axis=0), 0.0, atol=1e-8)


def test_a_richer_form_misfits_less_and_a_bad_form_is_refused():
    rms = {
        form: np.sqrt(np.mean(form_misfit_deg(DESIGN, PITCH, ROLL, form=form) ** 2))
        for form in ("poly1", "poly3")
    }
    assert rms["poly3"] < rms["poly1"]  # poly3's terms include poly1's: never worse
    with pytest.raises(InputError, match="unknown model"):
        form_misfit_deg(DESIGN, PITCH, ROLL, form="cubic")
