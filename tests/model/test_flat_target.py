"""Flat-target curves and couplings (model.flat_target): the curve's checks, its readings that
carry a signal, the modelled flat coupling and the measured-over-modelled correction."""

import numpy as np
import pytest

from reflector_opt.model._flat_target import (
    MIN_SIGNAL_V,
    MeasuredCurve,
    flat_correction,
    flat_coupling,
    signal_readings,
)
from reflector_opt.model._sensors import NJL5901R_2 as NJL
from reflector_opt.util._errors import InputError

DISTANCE = np.array([0.5, 1.0, 1.5, 2.0, 3.0])


@pytest.mark.parametrize(
    ("keywords", "message"),
    [
        ({"distance_mm": (1, 2, 3), "volts": (1, 2, 3)}, "at least 4"),
        ({"volts": (1, 2, np.nan, 3)}, "must be finite"),
        ({"distance_mm": (1, 2, 2, 3)}, "strictly increasing"),
        ({"reflectance": 0.0}, r"reflectance must be in \(0, 1\]"),
        ({"specular_fraction": 1.5}, r"specular_fraction must be in \[0, 1\]"),
    ],
)
def test_a_malformed_curve_is_refused(keywords, message):
    fields = {"distance_mm": (1.0, 2.0, 3.0, 4.0), "volts": (1.0, 2.0, 2.5, 3.0), **keywords}
    with pytest.raises(InputError, match=f"^measured curve: .*{message}"):
        MeasuredCurve(**fields)


def test_a_curve_round_trips_through_its_dict():
    curve = MeasuredCurve((1.0, 2.0, 3.0, 4.0), (1.0, 2.0, 2.5, 3.0), 0.8, 0.25)
    data = curve.to_dict()
    assert data == {
        "distance_mm": [1.0, 2.0, 3.0, 4.0],
        "volts": [1.0, 2.0, 2.5, 3.0],
        "reflectance": 0.8,
        "specular_fraction": 0.25,
    }
    assert (
        MeasuredCurve(**{k: tuple(v) if isinstance(v, list) else v for k, v in data.items()})
        == curve
    )


def test_signal_readings_are_those_between_the_clamps():
    # NJL5901R-2's read-out: saturation 0.2 V, supply 3.3 V; both clamps excluded.
    volts = [3.3, 2.0, 0.2, 2.5, 1.0, 3.2, 0.1]
    assert np.flatnonzero(signal_readings(volts, NJL, "c")).tolist() == [1, 3, 4, 5]
    # A 0.15 V margin also drops 3.2 V (within 0.15 V of the supply).
    used = signal_readings(volts, NJL, "c", least=3, clamp_margin_v=0.15)
    assert np.flatnonzero(used).tolist() == [1, 3, 4]
    with pytest.raises(InputError, match=r"^c: needs at least 5 readings .* found 4$"):
        signal_readings(volts, NJL, "c", least=5)
    with pytest.raises(InputError, match=r"^c: every reading is clamped"):
        signal_readings([3.3, 0.2, 3.4], NJL, "c")
    flat = [2.0, 2.0 + 0.9 * MIN_SIGNAL_V, 2.0, 2.0]
    with pytest.raises(InputError, match=r"^c: the output does not change with the distance"):
        signal_readings(flat, NJL, "c")


def test_flat_coupling_mixes_mirror_and_lambertian_parts_by_the_equation():
    # η = ρ·[f·η_mirror + (1 − f)·η_Lambert]
    mirror = flat_coupling(NJL, DISTANCE)
    lambertian = flat_coupling(NJL, DISTANCE, 1.0, 0.0)
    mixed = flat_coupling(NJL, DISTANCE, 0.8, 0.3)
    np.testing.assert_allclose(mixed, 0.8 * (0.3 * mirror + 0.7 * lambertian), rtol=1e-12)
    assert np.all(mirror > 0) and np.all(lambertian > 0)
    assert not np.allclose(mirror, lambertian, rtol=1e-2)


def test_flat_correction_is_the_measured_over_modelled_ratio():
    assert flat_correction(NJL, DISTANCE) == 1.0  # no curve
    # A curve that reads twice the modelled coupling at ρ = 0.9: the correction is 2, also
    # between and beyond the points. At 0.5 mm twice the coupling saturates the output
    # (0.2 V): that point carries no coupling and is left out.
    volts = NJL.output_voltage(2 * flat_coupling(NJL, DISTANCE, 0.9))
    assert volts[0] == NJL.saturation_v
    model = NJL.with_(measured_curve=MeasuredCurve(tuple(DISTANCE), tuple(volts), 0.9))
    np.testing.assert_allclose(flat_correction(model, [0.5, 1.2, 2.0, 5.0]), 2.0, rtol=1e-9)
    same = NJL.with_(
        measured_curve=MeasuredCurve(
            tuple(DISTANCE), tuple(NJL.output_voltage(flat_coupling(NJL, DISTANCE, 0.9))), 0.9
        )
    )
    np.testing.assert_allclose(flat_correction(same, DISTANCE), 1.0, rtol=1e-9)
