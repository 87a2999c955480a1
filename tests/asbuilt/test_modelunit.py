"""The simulated units a plan is checked on (asbuilt.modelunit): units of the identification's
own model, built units, and the parameters an identification of either should find."""

import numpy as np
import pytest

from reflector_opt.asbuilt._modelunit import ModelUnit, simulated_units, true_parameters
from reflector_opt.asbuilt._parameters import ParameterLayout, true_deviations
from reflector_opt.model._forward import voltages
from reflector_opt.tolerance._builtunit import BuiltUnit
from reflector_opt.util._errors import InputError


@pytest.fixture(scope="module")
def layout(design):
    return ParameterLayout(design, 1)


def test_a_model_unit_is_its_parameters_drawn_within_the_bounds(layout, design):
    unit = ModelUnit.draw(layout, 3, seed=5)
    lower, upper = layout.bounds()
    assert unit.index == 3 and unit.x.shape == (layout.size,)
    assert np.all(unit.x >= lower) and np.all(unit.x <= upper) and np.any(unit.x != 0)
    np.testing.assert_array_equal(ModelUnit.draw(layout, 3, seed=5).x, unit.x)  # seeded
    assert not np.array_equal(ModelUnit.draw(layout, 4, seed=5).x, unit.x)
    # Independent path: the deviations read back from the unit's design and mismatch, as a
    # built unit's are, are the drawn vector.
    surface = [
        unit.design.reflector.reflectance - design.reflector.reflectance,
        unit.design.reflector.specular_fraction - design.reflector.specular_fraction,
    ]
    read_back = np.r_[surface, true_deviations(design, unit.design, unit.mismatch)]
    np.testing.assert_allclose(read_back, unit.x, atol=1e-9)
    assert true_parameters(design, unit) is unit.x
    # Its voltages are the fast model's with its gain and offset.
    np.testing.assert_allclose(
        unit.volts(5.0, -3.0), unit.mismatch.apply(voltages(unit.design, 5.0, -3.0))
    )


def test_simulated_units_of_each_truth(layout):
    model = simulated_units(layout, "model", 2, seed=1)
    assert [type(u) for u in model] == [ModelUnit, ModelUnit]
    assert [u.index for u in model] == [0, 1]
    np.testing.assert_array_equal(model[1].x, ModelUnit.draw(layout, 1, seed=1).x)
    (built,) = simulated_units(layout, "built", 1, seed=1)
    assert isinstance(built, BuiltUnit)
    with pytest.raises(InputError, match=r"^truth: expected 'built' or 'model', got 'real'$"):
        simulated_units(layout, "real", 1, seed=1)
