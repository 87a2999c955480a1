"""Sweeps of a design's numbers: the variable's syntax, whole numbers, each point, invalid ones."""

import math
import re
from concurrent.futures import ThreadPoolExecutor

import pytest

from reflector_opt.design import Design
from reflector_opt.tolerance import (
    Job,
    Tolerances,
    draw_sample,
    evaluate_draw,
)
from reflector_opt.tolerance._sweep import parse_variable, set_value, sweep
from reflector_opt.util._errors import InputError
from reflector_opt.util._pools import supplied
from tests.tolerance.fast import FAST


def test_parse_variable_and_set_value(design):
    assert parse_variable("reflector.radius_mm=8.5:9.5:3") == (
        "reflector.radius_mm",
        [8.5, 9.0, 9.5],
    )
    assert parse_variable("sensors[1].axis[0]=0.1,-0.2") == ("sensors[1].axis[0]", [0.1, -0.2])
    doc = set_value(design.to_dict(), "sensors[1].position_mm[1]", 9.5)
    assert doc["sensors"][1]["position_mm"] == [0.0, 9.5, 0.0]
    assert design.sensors[1].position_mm == (0.0, 10.0, 0.0)  # the original is untouched
    for spec, message in (
        ("reflector.radius_mm", "expected PATH="),
        ("reflector.radius_mm=1:2", "START:STOP:N"),
        ("reflector.radius_mm=1,x", "START:STOP:N"),
        ("reflector.radius_mm=1,inf", "finite"),
        ("reflector..radius_mm=1", "path like"),
    ):
        with pytest.raises(InputError, match=re.escape(message)):
            parse_variable(spec)
    for path in ("reflector.radius", "sensors[5].axis[0]", "sensors[0].model"):
        with pytest.raises(InputError, match=re.escape(path)):
            set_value(design.to_dict(), path, 1.0)


def test_a_whole_number_of_the_design_is_swept_as_one(design):
    """--vary mechanics.n_units=2,4 marked every point invalid: 'expected a whole number
    from 1 to 1000, got 2.0'."""
    doc = set_value(design.to_dict(), "mechanics.n_units", 2.0)
    assert doc["mechanics"]["n_units"] == 2 and isinstance(doc["mechanics"]["n_units"], int)
    assert Design.from_dict(doc).mechanics.n_units == 2
    doc = set_value(design.to_dict(), "mechanics.n_units", 2.5)  # refused by the design
    with pytest.raises(
        InputError, match=r"mechanics\.n_units: expected a whole number from 1 to 1000, got 2\.5"
    ):
        Design.from_dict(doc)
    radius = set_value(design.to_dict(), "reflector.radius_mm", 9.0)["reflector"]["radius_mm"]
    assert isinstance(radius, float)  # a float of the design stays a float


def test_sweep_reports_each_point_and_invalid_ones(design):
    variables = [("reflector.radius_mm", [9.0, 8.5]), ("sensors[0].position_mm[0]", [10.0, 5.0])]
    with ThreadPoolExecutor(2) as pool:
        rows = sweep(design, variables, samples=2, seed=1, settings=FAST, factory=supplied(pool))
    assert [(r["reflector.radius_mm"], r["sensors[0].position_mm[0]"]) for r in rows] == [
        (9.0, 10.0),
        (9.0, 5.0),
        (8.5, 10.0),
        (8.5, 5.0),
    ]
    assert rows[1]["status"].startswith("invalid: sensors: S1")  # 5 mm from O: inside the sphere
    assert math.isnan(rows[1]["nominal_rms_pitch_deg"])
    nominal = evaluate_draw(
        Job(design, Tolerances.zero(), FAST), draw_sample(Tolerances(), 2, 1, 0)
    )
    assert rows[0]["nominal_rms_pitch_deg"] == nominal["rms_pitch_deg"]
    assert 0 <= rows[0]["yield"] <= 1
