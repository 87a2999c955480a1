"""Sensor presets: the datasheet response shape and the look-up by name."""

import numpy as np
import pytest

from reflector_opt.model.optics import beam_radius, gaussian_power
from reflector_opt.model.sensors import PRESETS, get_preset
from reflector_opt.util.errors import InputError


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
