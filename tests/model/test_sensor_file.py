"""A sensor model's checks and dict form: bad values, the round trip and bad keys."""

import pytest

from reflector_opt.model._sensors import NJL5901R_2, SensorModel
from reflector_opt.util._errors import InputError


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"emitter_detector_mm": 0.0}, "emitter_detector_mm must be positive"),
        ({"divergence_deg": 95.0}, "divergence_deg"),
        ({"range_mm": (3.0, 0.5)}, "range_mm"),
        ({"led_forward_v": 4.0}, "led_forward_v"),
        ({"current_gain": float("nan")}, "current_gain: must be finite, got nan"),
    ],
)
def test_invalid_parameters_are_rejected(change, message):
    with pytest.raises(InputError, match=message):
        NJL5901R_2.with_(**change)


def test_dict_round_trip_and_bad_keys():
    m = NJL5901R_2
    assert SensorModel.from_dict(m.to_dict()) == m
    with pytest.raises(InputError, match="unknown key"):
        SensorModel.from_dict({**m.to_dict(), "colour": "red"})
    data = m.to_dict()
    del data["current_gain"]
    with pytest.raises(InputError, match=r"current_gain: missing key"):
        SensorModel.from_dict(data)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            {"dark_current_a": float("nan")},
            "sensor_models.X.dark_current_a: expected a number from 0 to 1 A, got nan",
        ),
        ({"dark_current_a": -1e-9}, "dark_current_a: expected a number from 0 to 1 A, got -1e-09"),
        (
            {"range_mm": [0.5, float("inf")]},
            "range_mm[1]: expected a number from 0 to 1000 mm, got inf",
        ),
        (
            {"range_mm": [0.5, 5000.0]},
            "range_mm[1]: expected a number from 0 to 1000 mm, got 5000.0",
        ),
        (
            {"emitter_detector_mm": 1e308},
            "emitter_detector_mm: expected a number > 0 and ≤ 1000 mm, got 1e+308",
        ),
        (
            {"saturation_v": 10**400},
            "saturation_v: expected a number from 0 to 1000 V, got 1000000000000",
        ),
    ],
)
def test_nonsense_read_from_a_dict_is_refused(change, message):
    with pytest.raises(InputError) as exc:
        SensorModel.from_dict({**NJL5901R_2.to_dict(), **change}, "sensor_models.X")
    assert message in str(exc.value)
