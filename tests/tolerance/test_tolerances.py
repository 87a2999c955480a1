"""The tolerance model: draws by seed and index, uniform spreads, the built unit, bad tolerances."""

import math
import re

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.tolerance import (
    Spread,
    Tolerances,
    as_built,
    draw_sample,
)
from reflector_opt.util._errors import InputError


def test_draw_depends_only_on_seed_and_index():
    a = draw_sample(Tolerances(), 2, seed=7, index=3)
    b = draw_sample(Tolerances.zero(), 2, seed=7, index=3)  # scales do not change the draws
    c = draw_sample(Tolerances(), 2, seed=7, index=4)
    for name in Tolerances.names():
        assert np.array_equal(a.standard[name], b.standard[name])
    assert a.noise_seed == b.noise_seed
    assert not np.array_equal(a.standard["gain"], c.standard["gain"])
    assert a.standard["sensor_position_mm"].shape == (6,)
    assert a.standard["sensor_tilt_deg"].shape == (4,)


def test_uniform_draws_stay_within_their_half_width(design):
    tol = Tolerances(crosstalk_fraction=Spread(0.03, "uniform"))
    coarse = design.replace(workspace=type(design.workspace)(step_deg=1.0))
    values = []
    for i in range(100):
        _, electrical = as_built(coarse, tol, draw_sample(tol, 2, 0, i))
        values.append(electrical.crosstalk_fraction)
    values = np.concatenate(values)
    assert values.min() >= 0 and values.max() <= 0.03  # one-sided: |U(−w, w)|
    assert values.max() > 0.025 and values.min() < 0.005


def test_as_built_hand_values(design):
    tol = Tolerances.zero()
    draw = draw_sample(tol, 2, 0, 0)
    standard = {name: np.zeros_like(v) for name, v in draw.standard.items()}
    standard["reflector_radius_mm"] = np.array([2.0])
    standard["centre_offset_mm"] = np.array([1.0, -1.0, 0.5])
    standard["sensor_position_mm"] = np.array([1.0, 0, 0, 0, -2.0, 0])
    standard["sensor_tilt_deg"] = np.array([1.0, 0, 1.0, 1.0])
    standard["gain"] = np.array([1.0, -1.0])
    standard["crosstalk_fraction"] = np.array([-1.0, 0.5])
    tol = Tolerances(
        **{name: Spread(0.0) for name in Tolerances.names()}
        | {
            "reflector_radius_mm": Spread(0.01),
            "centre_offset_mm": Spread(0.02),
            "sensor_position_mm": Spread(0.05),
            "sensor_tilt_deg": Spread(2.0),
            "gain": Spread(0.03),
            "crosstalk_fraction": Spread(0.01, "uniform"),
        }
    )
    built, electrical = as_built(design, tol, type(draw)(0, standard, draw.noise_seed))
    assert built.reflector.radius_mm == pytest.approx(9.02)
    assert_allclose(built.reflector.centre_mm, (0.02, -0.02, -1.4 + 0.01))
    assert_allclose(built.sensors[0].position_mm, (10.05, 0, 0))
    assert_allclose(built.sensors[1].position_mm, (0, 9.9, 0))

    def angle(a, b):
        a, b = np.asarray(a) / np.linalg.norm(a), np.asarray(b) / np.linalg.norm(b)
        return np.degrees(np.arccos(np.clip(a @ b, -1, 1)))

    assert angle(built.sensors[0].axis, design.sensors[0].axis) == pytest.approx(2.0)
    # two perpendicular tilts of 2°: tan θ = √2 · tan 2°
    expected = np.degrees(np.arctan(math.sqrt(2) * math.tan(math.radians(2.0))))
    assert angle(built.sensors[1].axis, design.sensors[1].axis) == pytest.approx(expected)
    assert electrical.mismatch.gain == pytest.approx((1.03, 0.97))
    assert_allclose(electrical.crosstalk_fraction, [0.01, 0.005])
    multiplexed = as_built(design, Tolerances(multiplexed=True), draw)[1]
    assert np.all(multiplexed.crosstalk_fraction == 0)


@pytest.mark.parametrize(
    "data, message",
    [
        (
            {"gain": -0.01},
            "tolerances.gain: expected a number from 0 to 1000 or a table, got -0.01",
        ),
        (
            {"crosstalk_fraction": {"scale": -1}},
            "tolerances.crosstalk_fraction.scale: expected a number from 0 to 1000, got -1",
        ),
        (
            {"gain": {"scale": 0.01, "kind": "lognormal"}},
            "tolerances.gain.kind: expected one of 'normal', 'uniform', got 'lognormal'",
        ),
        ({"gian": 0.01}, "[tolerances]: unknown key(s) gian; allowed: reflector_radius_mm"),
        (
            {"gain": {"sigma": 0.01}},
            "[tolerances.gain]: unknown key(s) sigma; allowed: scale, kind",
        ),
        ({"multiplexed": "yes"}, "multiplexed"),
        ({"gain": float("nan")}, "tolerances.gain"),
    ],
)
def test_bad_tolerances(data, message):
    with pytest.raises(InputError, match=re.escape(message)):
        Tolerances.from_dict(data)
