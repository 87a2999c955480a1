"""The one factory of calibration models from a form's name (calibration.estimators)."""

import numpy as np
import pytest

from reflector_opt.calibration._estimators import make_estimator, selected
from reflector_opt.calibration._models import Eq5, Eq6, Polynomial
from reflector_opt.calibration._physical import PhysicalModel
from reflector_opt.calibration._selection import AutoModel
from reflector_opt.design import default_design
from reflector_opt.util._errors import InputError


def test_each_name_gives_its_unfitted_model():
    assert type(make_estimator("eq5")) is Eq5
    assert type(make_estimator(" EQ6 ")) is Eq6  # case and spaces as a user types them
    poly = make_estimator("poly4", fit="huber")
    assert type(poly) is Polynomial
    assert poly.get_params()["degree"] == 4 and poly.get_params()["loss"] == "huber"
    auto = make_estimator("auto", fit="minimax", folds=3, seed=7)
    assert type(auto) is AutoModel
    assert (auto.loss, auto.folds, auto.seed) == ("minimax", 3, 7)
    design = default_design()
    physical = make_estimator("Physical", design=design)
    assert type(physical) is PhysicalModel
    assert not hasattr(physical, "coef_") and not hasattr(auto, "selected_")


@pytest.mark.parametrize(
    ("form", "keywords", "fragment"),
    [
        ("physical", {}, "needs the units' design"),
        ("physical", {"fit": "huber", "design": default_design()}, "least squares only"),
        ("eq7", {}, "unknown model 'eq7'"),
        ("poly11", {}, "degree must be a whole number from 1 to 10"),
    ],
)
def test_bad_forms_are_refused(form, keywords, fragment):
    with pytest.raises(InputError, match=fragment):
        make_estimator(form, **keywords)


def test_selected_is_the_form_auto_chose_else_the_model():
    # Angles exactly linear in the voltages: every candidate fits them, and selected() must
    # return the fitted candidate auto chose (not auto itself), which predicts them back.
    rng = np.random.default_rng(1)
    volts = rng.uniform(0.5, 2.0, size=(40, 2))
    angles = volts @ np.array([[10.0, -3.0], [2.0, 8.0]]) + np.array([1.0, -2.0])
    auto = make_estimator("auto", folds=3).fit(volts, angles)
    chosen = selected(auto)
    assert chosen is auto.selected_ and not isinstance(chosen, AutoModel)
    np.testing.assert_allclose(chosen.predict(volts), angles, atol=1e-6)
    eq6 = make_estimator("eq6")
    assert selected(eq6) is eq6
