"""Sensor presets: the datasheet response shape and the look-up by name."""

import dataclasses

import numpy as np
import pytest

from reflector_opt.model._sensors import PRESETS, get_preset
from reflector_opt.util._errors import InputError


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_flat_reflector_response_is_monotonic_over_the_usable_range(name):
    """Datasheet shape: peak just below the near end, then voltage rising with distance."""
    m = get_preset(name)
    lo, hi = m.range_mm
    d = np.linspace(0.05 * lo, hi, 400)
    v = m.output_voltage(m.flat_coupling(d, reflectance=0.9, specular_fraction=1.0))
    peak = d[np.argmin(v)]
    assert 0.5 * lo < peak < lo
    usable = d >= lo
    assert np.all(np.diff(v[usable]) > 0)
    assert v[usable][-1] - v[usable][0] > 0.5 * (m.supply_v - m.saturation_v)  # a usable swing


def test_unknown_preset_names_the_known_ones():
    with pytest.raises(InputError, match=r"unknown sensor preset 'XYZ'.*NJL5901R-2"):
        get_preset("XYZ")


def test_unknown_name_lists_the_catalogue_parts_too():
    from reflector_opt.model._catalogue import sensor_model

    assert sensor_model("QRE1113") is PRESETS["QRE1113"]
    with pytest.raises(InputError, match=r"catalogue's parts: .*VCNT2020.*CNY70"):
        sensor_model("XYZ")


def test_a_design_may_name_a_catalogue_part(design):
    """A design.json naming a catalogue part was refused: only the two presets were known."""
    from reflector_opt.model._catalogue import get_part

    sensors = [dataclasses.replace(s, model="VCNT2020") for s in design.sensors]
    models = design.replace(sensors=sensors).models
    assert models[0] is get_part("VCNT2020").model and models[0].name == "VCNT2020"
    assert models[0].emitter_detector_mm != get_preset("NJL5901R-2").emitter_detector_mm
