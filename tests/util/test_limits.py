"""The limits on sizes and counts: refused with the parameter and the limit named."""

import math

import pytest

from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import check_count, check_size, check_within, grid_poses


def test_check_size_names_the_parameter_the_size_and_the_limit():
    assert check_size(10, "n", 10, "poses") == 10
    with pytest.raises(InputError, match=r"^--samples: asks for 1,001 units, more than the limit"):
        check_size(1001, "--samples", 1000, "units")
    with pytest.raises(InputError, match="asks for 1e\\+20 poses"):
        check_size(1e20, "step", 1000, "poses")
    for bad in (math.inf, math.nan):
        with pytest.raises(InputError):
            check_size(bad, "step", 1000, "poses")


@pytest.mark.parametrize("value", [2.5, "3", True, None, math.nan, math.inf, -1, 11])
def test_check_count_refuses_what_is_not_a_whole_number_in_range(value):
    with pytest.raises(InputError, match=r"^n_units: must be a whole number from 0 to 10"):
        check_count(value, "n_units", 0, 10)


def test_check_count_accepts_whole_floats():
    assert check_count(4.0, "n", 1, 10) == 4 and isinstance(check_count(4.0, "n", 1, 10), int)


def test_grid_poses():
    assert grid_poses((30.0, 30.0), 0.1) == 301 * 301
    assert grid_poses((30.0, 10.0), 1.0) == 31 * 11
    assert grid_poses((30.0, 30.0), 1e-320) == math.inf


def test_an_integer_of_many_digits_is_named_by_its_size():
    with pytest.raises(InputError, match=r"got about 1e5000$"):
        check_count(10**5000, "n", 0, 10)
    with pytest.raises(InputError, match=r"got about -1e30$"):
        check_count(-(10**30), "n", 0, 10)


def test_check_within_keeps_the_bound_unless_strict():
    assert check_within(-1000.0, "v1", 1000.0, " V") == -1000.0
    with pytest.raises(InputError, match=r"^pitch: expected a number > -90 and < 90°, got 90.0$"):
        check_within(90.0, "pitch", 90.0, "°", strict=True)
    assert check_within(89.9, "pitch", 90.0, "°", strict=True) == 89.9


@pytest.mark.parametrize("value", [1000.5, -1e308, math.inf, math.nan])
def test_check_within_names_the_field_the_range_and_what_was_written(value):
    with pytest.raises(
        InputError, match=r"^f, line 3: expected a number from -1000 to 1000 V, got x$"
    ):
        check_within(value, "f, line 3", 1000.0, " V", given="x")
