"""The optimisation problem: fixed variables and the refusal of bad problems."""

import pytest

from reflector_opt.optimiser import Problem
from reflector_opt.util._errors import InputError


def test_fixed_variables_are_not_searched():
    problem = Problem(bounds={"sensor_tilt_deg": (5.0, 5.0)})
    assert "sensor_tilt_deg" not in problem.free_names
    assert problem.fixed_values["sensor_tilt_deg"] == 5.0


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"bounds": {"centre_z_mm": (1.0, -1.0)}}, "min 1.0 is greater than max -1.0"),
        ({"bounds": {"size": (1.0, 2.0)}}, "bounds.size: unknown design variable"),
        (
            {"distance_margin_mm": -0.1},
            "distance_margin_mm: expected a number from 0 to 1000 mm, got -0.1",
        ),
        ({"distance_margin_mm": 1.3}, "distance window"),
        ({"bounds": {"sensor_radius_mm": (10.5, 12.0)}}, "sensor envelope"),
        ({"bearing_clearance_mm": 2.5}, "wall"),
    ],
)
def test_bad_problems_are_refused_with_the_reason(kwargs, fragment):
    with pytest.raises(InputError) as err:
        Problem(**kwargs)
    assert fragment in str(err.value)


def test_problem_refuses_cad_parameters_of_the_wrong_type():
    with pytest.raises(InputError, match="cad: expected CadParameters"):
        Problem(cad={"clearance_mm": 0.2})
