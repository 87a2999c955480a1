"""The conditions file: defaults, the example, and bad values refused naming the key."""

import math
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from reflector_opt.design._conditions import Conditions, load_conditions, parse_conditions
from reflector_opt.util._errors import InputError

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "conditions.toml"


def test_an_empty_file_is_a_bench_at_room_temperature():
    conditions = parse_conditions({})
    assert conditions == Conditions()
    assert conditions.drive == "dc" and conditions.temperature_range_k == 2.0


def test_the_example_file_reads():
    conditions = load_conditions(EXAMPLE)
    assert conditions.temperature_range_k == 5.0
    assert (conditions.joint_clearance_um, conditions.tendon_preload_n) == (68.0, 1.0)
    assert (conditions.supply_change_mv, conditions.adc_reference) == (10.0, "fixed")
    assert conditions.reference_zero_deg == [0.1, 0.1]
    assert parse_conditions({"conditions": conditions.to_dict()}) == conditions


@pytest.mark.parametrize(
    ("table", "key"),
    [
        ({"temperature_range_k": -1.0}, "temperature_range_k"),
        ({"temperature_range_k": 80.0}, "temperature_range_k"),  # an absolute temperature
        ({"drive": "pwm"}, "drive"),
        ({"ambient_mv": math.nan}, "ambient_mv"),
        ({"ambient_mv": 0.002}, "ambient_mv"),  # volts for millivolts
        ({"ambient_flicker_mv": 0.001}, "ambient_flicker_mv"),
        ({"reference_zero_deg": [0.0017, 0.0017]}, "reference_zero_deg"),  # radians
        ({"reference_zero_deg": [45.0, 0.0]}, "reference_zero_deg"),
        ({"resin_cte_ppm_per_k": -1.0}, "resin_cte_ppm_per_k"),
        ({"strip_cte_ppm_per_k": math.nan}, "strip_cte_ppm_per_k"),
        ({"strip_cte_ppm_per_k": 1.3e-5}, "strip_cte_ppm_per_k"),  # per kelvin for ppm/K
        ({"angle_reference": "laser"}, "angle_reference"),
        ({"angle_reference": "stated"}, "reference_zero_deg"),  # a stated zero not given
        ({"joint_play_um": 5.0}, "joint_clearance_um"),  # the retired key names the new one
        ({"joint_clearance_um": -1.0}, "joint_clearance_um"),
        ({"joint_clearance_um": 5000.0}, "joint_clearance_um"),  # mm given as µm
        ({"joint_clearance_um": 0.03}, "joint_clearance_um"),  # mm for µm
        ({"joint_clearance_um": math.nan}, "joint_clearance_um"),
        ({"tendon_preload_n": -1.0}, "tendon_preload_n"),
        ({"load_reverses": "yes"}, "load_reverses"),
        ({"supply_change_mv": 0.01}, "supply_change_mv"),  # volts for millivolts
        ({"supply_change_mv": math.inf}, "supply_change_mv"),
        ({"adc_reference": "vcc"}, "adc_reference"),
        ({"hours_since_calibration": -5.0}, "hours_since_calibration"),
        ({"thermometer_lag_s": 5000.0}, "thermometer_lag_s"),  # ms given as s
        ({"thermometer_offset_k": math.nan}, "thermometer_offset_k"),
        ({"temperature_rate_k_per_min": -1.0}, "temperature_rate_k_per_min"),
        ({"strip_gradient_k": 50.0}, "strip_gradient_k"),
        ({"temperature_compensated": 1.5}, "temperature_compensated"),
        ({"sample_rate_hz": 0.0}, "sample_rate_hz"),
        ({"unknown_key": 1.0}, "unknown_key"),
    ],
)
def test_bad_values_are_refused_with_one_line_naming_the_key(table, key):
    with pytest.raises(InputError) as error:
        parse_conditions({"conditions": table})
    message = str(error.value)
    assert key in message and "\n" not in message


@given(st.dictionaries(st.sampled_from(list(Conditions().to_dict())), st.floats()))
def test_any_numbers_give_conditions_or_one_input_error(table):
    try:
        conditions = parse_conditions({"conditions": table})
    except InputError as error:
        assert "\n" not in str(error)
    else:
        assert all(math.isfinite(v) for v in conditions.to_dict().values() if isinstance(v, float))
