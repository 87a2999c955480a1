"""K-fold cross-validation of the calibration models."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.calibration._models import Eq6
from reflector_opt.calibration._validation import cross_validate
from reflector_opt.util._errors import InputError
from tests.calibration.eq6_data import synthetic


def test_cross_validation_of_exact_and_noisy_data():
    volts, angles = synthetic(600)
    exact = cross_validate(Eq6(), volts, angles, folds=4)
    assert exact["folds"] == 4 and np.all(exact["rms_deg"] < 1e-8)
    noisy_volts, noisy_angles = synthetic(600, sigma_deg=0.2)
    cv = cross_validate(Eq6(), noisy_volts, noisy_angles, folds=5)
    train = Eq6().fit(noisy_volts, noisy_angles).training_rms_deg_
    assert np.all(cv["rms_deg"] > train)  # held-out error exceeds training error
    assert_allclose(cv["rms_deg"], 0.2, rtol=0.1)


def test_cross_validation_names_the_failing_fold():
    volts, angles = synthetic(10)
    with pytest.raises(InputError, match="fold 1 of 3"):
        cross_validate(Eq6(), volts, angles, folds=3)  # 6 training samples < 8 coefficients
    with pytest.raises(InputError, match="folds"):
        cross_validate(Eq6(), volts, angles, folds=1)
