"""A sensor model's checks and dict form: bad values, the round trip and bad keys."""

import pytest

from reflector_opt.model.sensors import NJL5901R_2, SensorModel
from reflector_opt.util.errors import InputError


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"emitter_detector_mm": 0.0}, "emitter_detector_mm must be positive"),
        ({"divergence_deg": 95.0}, "divergence_deg"),
        ({"range_mm": (3.0, 0.5)}, "range_mm"),
        ({"led_forward_v": 4.0}, "led_forward_v"),
        ({"current_gain": float("nan")}, "current_gain must be positive"),
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
    with pytest.raises(InputError, match=r"missing key.*current_gain"):
        SensorModel.from_dict(data)
