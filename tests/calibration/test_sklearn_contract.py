"""scikit-learn's own estimator contract on every calibration model: ``sklearn.base.clone``
and the API checks of ``sklearn.utils.estimator_checks`` that need no scikit-learn data (the
models take two voltage columns and two angle columns, not the checks' datasets), and
``get_params``/``set_params`` round trips, nested (``form__loss``) included.

Each model is one of tests/calibration/test_estimator_contract.py's (every form a user can
name, the temperature-compensated ones, an identified unit's own model).
"""

import warnings

import pytest
from sklearn import base
from sklearn.utils import estimator_checks as checks

from reflector_opt.calibration._models import Eq6, Estimator, make_model
from reflector_opt.calibration._selection import AutoModel
from reflector_opt.calibration._temperature import TemperatureCompensated
from reflector_opt.util._errors import InputError
from tests.calibration.test_estimator_contract import FORMS, _estimator

#: The checks of scikit-learn's API that hold without its datasets.
API_CHECKS = (
    "check_estimator_cloneable",
    "check_estimator_repr",
    "check_no_attributes_set_in_init",
    "check_parameters_default_constructible",
    "check_get_params_invariance",
    "check_set_params",
    "check_do_not_raise_errors_in_init_or_set_params",
)


@pytest.mark.parametrize("check", API_CHECKS)
@pytest.mark.parametrize("form", FORMS)
def test_scikit_learns_api_checks_pass(form, check):
    model = _estimator(form)
    with warnings.catch_warnings():
        warnings.simplefilter("error", FutureWarning)  # no old name used on the way
        getattr(checks, check)(type(model).__name__, model)


@pytest.mark.parametrize("form", FORMS)
def test_scikit_learns_clone_gives_the_same_parameters_unfitted(form):
    model = _estimator(form)
    copy = base.clone(model)
    assert type(copy) is type(model) and copy is not model
    assert copy.get_params(deep=False).keys() == model.get_params(deep=False).keys()
    assert repr(copy) == repr(model)


@pytest.mark.parametrize("form", FORMS)
def test_set_params_of_get_params_changes_nothing(form):
    model = _estimator(form)
    deep = model.get_params(deep=True)
    assert model.get_params(deep=False).items() <= deep.items()
    assert model.set_params(**deep) is model
    assert model.get_params(deep=True).keys() == deep.keys()
    assert all(model.get_params(deep=True)[k] is v for k, v in deep.items())


def test_a_nested_parameter_is_set_on_the_inner_estimator():
    model = TemperatureCompensated(Eq6())
    assert model.get_params()["form__loss"] == "lsq"
    model.set_params(form__loss="huber", degree=2)
    assert model.form.loss == "huber" and model.degree == 2
    assert base.clone(model).form.loss == "huber"


def test_the_fit_parameter_is_loss_and_its_old_name_is_refused_or_deprecated():
    """``fit`` hid the method of the same name: scikit-learn's clone could not rebuild a
    model from ``get_params``. Its old name is an InputError naming ``loss`` where no page
    used it, and a FutureWarning for one release on the constructors the pages wrote it on."""
    assert make_model("poly3", "huber").loss == "huber"
    with pytest.raises(InputError, match=r"fit: not a parameter of Eq6 \(renamed loss\)"):
        Eq6().set_params(fit="huber")
    with pytest.raises(InputError, match=r"fit: renamed loss .*; pass AutoModel\(loss=\)"):
        AutoModel(fit="huber")
    with pytest.warns(FutureWarning, match=r"Eq6\(fit=\.\.\.\) is renamed Eq6\(loss=\.\.\.\)"):
        assert Eq6(fit="huber").loss == "huber"
    with pytest.raises(TypeError, match="unexpected keyword argument 'colour'"):
        Eq6(colour=1)
    with pytest.raises(InputError, match="degrees: not a parameter of Polynomial"):
        make_model("poly3").set_params(degrees=4)


def test_every_estimator_of_the_package_is_checked():
    """Every Estimator subclass with a public name is among the forms checked above."""

    def subclasses(cls):
        return {cls} | {s for c in cls.__subclasses__() for s in subclasses(c)}

    public = {c for c in subclasses(Estimator) if not c.__name__.startswith("_")}
    assert public - {Estimator} == {type(_estimator(form)) for form in FORMS}
