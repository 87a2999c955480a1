"""The value checks of a design's fields, each naming the field at fault (design.validation)."""

import math

import pytest

from reflector_opt.design._validation import (
    check_centre_inside,
    check_finite_tree,
    check_length,
    check_number,
    check_range,
    check_vector,
    reject_unknown,
    require_key,
)
from reflector_opt.util._errors import InputError


def test_check_number_returns_a_float_and_refuses_each_rule():
    assert check_number(3, "a.b") == 3.0 and type(check_number(3, "a.b")) is float
    assert check_number(-2.5, "a.b", bound=2.5) == -2.5  # the bound itself is allowed
    for value, keywords, message in [
        (True, {}, "a.b: expected a number, got True"),
        ("1", {}, "a.b: expected a number"),
        (math.nan, {}, "a.b: must be finite"),
        (0.0, {"positive": True}, "a.b: must be positive, got 0.0"),
        (-1e-9, {"nonnegative": True}, "a.b: must not be negative"),
        (-3.0, {"bound": 2.5, "unit": "mm"}, r"a.b: must be within ±2.5 mm, got -3"),
        (3.0, {"positive": True, "bound": 2.5}, r"a.b: must be at most 2.5, got 3"),
    ]:
        with pytest.raises(InputError, match=message):
            check_number(value, "a.b", **keywords)


def test_check_length_bounds_at_a_metre():
    assert check_length(1000.0, "r") == 1000.0
    with pytest.raises(InputError, match="r: must be at most 1000 mm"):
        check_length(1000.001, "r", positive=True)


def test_check_centre_inside_is_strict():
    check_centre_inside(5.0, (3.0, 0.0, 3.99))  # |c| = 4.99 mm < 5 mm
    with pytest.raises(InputError, match=r"reflector.centre_mm: .* is 5 mm from it"):
        check_centre_inside(5.0, (3.0, 0.0, 4.0))  # 3-4-5: on the sphere, refused


def test_check_vector_and_check_range():
    assert check_vector([1, 2, 3], "v") == (1.0, 2.0, 3.0)
    with pytest.raises(InputError, match=r"v: expected a list of 3 numbers, got \[1, 2\]"):
        check_vector([1, 2], "v")
    with pytest.raises(InputError, match=r"v\[1\]: must be within ±10 mm"):
        check_vector([0.0, 11.0, 0.0], "v", bound=10.0, unit="mm")
    assert check_range([-20, 20], "w.pitch_deg") == (-20.0, 20.0)
    with pytest.raises(InputError, match=r"w.pitch_deg: min must be below max, got \[5.0, 5.0\]"):
        check_range([5, 5], "w.pitch_deg")


def test_require_key_and_reject_unknown():
    assert require_key({"radius_mm": 9.0}, "radius_mm", "reflector.") == (
        9.0,
        "reflector.radius_mm",
    )
    with pytest.raises(InputError, match=r"^reflector.radius_mm: missing key$"):
        require_key({}, "radius_mm", "reflector.")
    with pytest.raises(InputError, match=r"^reflector: expected an object$"):
        require_key([9.0], "radius_mm", "reflector.")
    with pytest.raises(InputError, match=r"^design: expected an object$"):
        require_key(None, "reflector")
    reject_unknown({"a": 1}, ("a", "b"), "x")
    with pytest.raises(InputError, match=r"^x: unknown key\(s\) 'a b', c; allowed: a, b$"):
        reject_unknown({"a": 1, "c": 2, "a b": 3}, ("a", "b"), "x")


def test_check_finite_tree_names_the_path_of_a_non_finite_leaf():
    tree = {"predicted": {"rows": [1.0, {"x": 2.0}]}, "n": 3}
    assert check_finite_tree(tree, "design") is tree
    tree["predicted"]["rows"][1]["x"] = math.inf
    with pytest.raises(InputError, match=r"^design.predicted.rows\[1\].x: must be finite, got inf"):
        check_finite_tree(tree, "design")
