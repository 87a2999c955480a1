"""Physical ranges of a design's values and the size of its pose grids."""

import math

import pytest

from reflector_opt.design import Design, Mechanics, Workspace, default_design
from reflector_opt.design._components import Reflector, SensorPlacement
from reflector_opt.design._parts import CadParameters
from reflector_opt.util._errors import InputError


def _load(mutate):
    data = default_design().to_dict()
    mutate(data)
    return Design.from_dict(data)


@pytest.mark.parametrize(
    ("mutate", "message"),
    [
        (
            lambda d: d["sensors"][0].update(position_mm=[0.0, 1e308, 0.0]),
            "sensors[0].position_mm[1]: expected a number from -1000 to 1000 mm, got 1e+308",
        ),
        (
            lambda d: d["reflector"].update(centre_mm=[0.0, 0.0, -2000.0]),
            "reflector.centre_mm[2]: expected a number from -1000 to 1000 mm, got -2000.0",
        ),
        (
            lambda d: d["reflector"].update(inner_radius_mm=10**400),
            "reflector.inner_radius_mm: expected a number > 0 and ≤ 1000 mm, got 1000000000",
        ),
        (
            lambda d: d["mechanics"].update(link_length_mm=1e308),
            "mechanics.link_length_mm: expected a number > 0 and ≤ 1000 mm, got 1e+308",
        ),
        (
            lambda d: d["mechanics"].update(n_units=2.5),
            "mechanics.n_units: expected a whole number from 1 to 1000, got 2.5",
        ),
        (lambda d: d["mechanics"].update(n_units=10**9), "mechanics.n_units"),
        (lambda d: d["mechanics"].update(n_units=True), "mechanics.n_units"),
        (
            lambda d: d["sensors"][0].update(axis=[-1e200, 0.0, 0.0]),
            "sensors[0].axis[0]: expected a number from -1000000 to 1000000, got -1e+200",
        ),
        (
            lambda d: d["workspace"].update(step_deg=1e-7),
            "workspace.step_deg = 1e-07°: asks for 9e+16 grid poses",
        ),
        (lambda d: d["workspace"].update(step_deg=1e-320), "asks for inf grid poses"),
        (
            lambda d: d["predicted"].update(metrics={"rms": [1.0, math.nan]}),
            "predicted.metrics.rms[1]: must be finite, got nan",
        ),
    ],
)
def test_values_outside_their_physical_range_are_refused(mutate, message):
    with pytest.raises(InputError) as exc:
        _load(mutate)
    assert message in str(exc.value)


def test_a_whole_float_unit_count_is_read_as_an_int():
    mechanics = Mechanics.from_dict({"n_units": 6.0})
    assert mechanics.n_units == 6 and isinstance(mechanics.n_units, int)
    assert Mechanics(n_units=3.0).n_units == 3


def test_the_constructors_check_the_ranges_too():
    with pytest.raises(
        InputError, match=r"reflector\.radius_mm: expected a number > 0 and ≤ 1000 mm, got 5000\.0"
    ):
        Reflector(radius_mm=5000.0)
    with pytest.raises(InputError, match="position_mm"):
        SensorPlacement("S1", "NJL5901R-2", (1e9, 0.0, 0.0), (-1.0, 0.0, 0.0))
    with pytest.raises(InputError, match=r"cad\.clearance_mm: must be at most 1000 mm"):
        CadParameters(clearance_mm=1e6)
    with pytest.raises(InputError, match=r"cad\.sweep_margin_deg"):
        CadParameters(sweep_margin_deg=400.0)


def test_a_grid_step_is_checked_before_the_grid_is_allocated():
    workspace = Workspace()
    assert workspace.check_step(0.1, "step") == 301 * 301
    with pytest.raises(InputError, match=r"^step_deg = 1e-06°: asks for 900,000,060,000,001"):
        workspace.grid(1e-6)
    with pytest.raises(InputError, match="step_deg: must be positive"):
        workspace.axes(-1.0)
    narrow = Workspace(pitch_deg=(-1.0, 1.0), roll_deg=(0.0, 0.5), step_deg=0.002)
    assert narrow.check_step(0.002, "step") == 1001 * 251


def test_a_grid_step_must_reach_both_ends_of_the_ranges():
    """[search] grid_step_deg = 90 over ±15° searched on a grid of the one pose (-15°, -15°)
    and exited 0; a step of less than twice the range keeps both ends."""
    workspace = Workspace()
    with pytest.raises(
        InputError,
        match=r"^search\.grid_step_deg: expected less than twice the pitch range \(60°\), "
        r"got 90: the grid would not reach workspace\.pitch_deg\[1\]$",
    ):
        workspace.check_step(90.0, "search.grid_step_deg")
    assert workspace.check_step(59.0, "search.grid_step_deg") == 2 * 2
    assert [a.tolist() for a in workspace.axes(59.0)] == [[-15.0, 15.0], [-15.0, 15.0]]
    narrow_roll = Workspace(roll_deg=(0.0, 1.0))
    with pytest.raises(InputError, match=r"twice the roll range \(2°\), got 2:"):
        narrow_roll.check_step(2.0, "settings.metrics_step_deg")
