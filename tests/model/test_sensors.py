"""Sensor presets and the electronics: hand values and the datasheet response shape."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.model.optics import beam_radius, gaussian_power
from reflector_opt.model.sensors import NJL5901R_2, PRESETS, SensorModel, get_preset
from reflector_opt.util.errors import InputError


def test_led_current_and_output_voltage_hand_values():
    m = NJL5901R_2
    assert_allclose(m.led_current_a, (3.3 - 1.2) / 680)  # 3.088 mA through R1 = 680 Ω
    eta = 0.01
    i_c = 2.4 * (2.1 / 680) * 0.01  # G · I_F · η = 74.1 µA
    assert_allclose(m.collector_current(eta), i_c)
    assert_allclose(m.output_voltage(eta), 3.3 - i_c * 10_000)  # R2 = 10 kΩ
    assert_allclose(m.output_voltage(0.0), 3.3)  # dark: the output sits at Vcc
    assert_allclose(m.output_voltage(1.0), 0.2)  # flooded: clamped at V_CE(sat)


def test_more_light_gives_lower_voltage_and_inverse_round_trips():
    m = NJL5901R_2
    eta = np.linspace(0.0, 0.03, 50)
    v = m.output_voltage(eta)
    assert np.all(np.diff(v) < 0)
    assert_allclose(m.coupling_from_voltage(v), eta, atol=1e-15)


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_flat_reflector_response_is_monotonic_over_the_usable_range(name):
    """Datasheet shape: peak just below the near end, then voltage rising with distance."""
    m = get_preset(name)
    lo, hi = m.range_mm
    d = np.linspace(0.05 * lo, hi, 2000)
    w = beam_radius(d, m.source_radius_mm, m.divergence_deg)
    v = m.output_voltage(0.9 * gaussian_power(1.0, m.detector_area_mm2, w, m.emitter_detector_mm))
    peak = d[np.argmin(v)]
    assert 0.5 * lo < peak < lo
    usable = d >= lo
    assert np.all(np.diff(v[usable]) > 0)
    assert v[usable][-1] - v[usable][0] > 0.5 * (m.supply_v - m.saturation_v)  # a usable swing


def test_unknown_preset_names_the_known_ones():
    with pytest.raises(InputError, match=r"unknown sensor preset 'XYZ'.*NJL5901R-2"):
        get_preset("XYZ")


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
