"""The names of the calibration fits (calibration.choices): each one fits, no other does."""

import numpy as np
import pytest

from reflector_opt.calibration._choices import FITS
from reflector_opt.calibration._models import make_model
from reflector_opt.util._errors import InputError


@pytest.mark.parametrize("fit", FITS)
def test_every_listed_fit_fits(fit):
    # Angles exactly linear in the voltages: every fit recovers them.
    rng = np.random.default_rng(0)
    volts = rng.uniform(0.5, 2.5, size=(12, 2))
    angles = volts @ np.array([[4.0, -1.0], [1.5, 3.0]]) + np.array([0.5, -0.25])
    model = make_model("poly1", fit).fit(volts, angles)
    np.testing.assert_allclose(model.predict(volts), angles, atol=1e-4)


def test_a_fit_not_listed_is_refused_naming_the_listed_ones():
    assert FITS == ("lsq", "huber", "minimax")
    with pytest.raises(InputError, match=r"^unknown fit 'l1'; choose one of lsq, huber, minimax$"):
        make_model("poly1", "l1")
