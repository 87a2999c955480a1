"""The detector's settling under switched drives, by hand."""

import math

import pytest

from reflector_opt.model import _catalogue as catalogue
from reflector_opt.model._drive import drive_effects
from reflector_opt.model._settling import (
    LOAD_EXPONENT,
    crosstalk_left,
    residues,
    settled_share,
    settling_rate_hz,
    time_constants_s,
)
from reflector_opt.util._errors import InputError


def test_the_vcnt2020_s_time_constant_at_its_load_by_hand():
    # t_f 15 µs at 100 Ω (Vishay doc 84285): τ = 15 µs / ln 9 = 6.827 µs at 100 Ω; at the
    # circuit's 9108 Ω, × (9108/100)^0.7 = 23.53: 160.6 µs
    rise, fall, load, assumed = catalogue.switching_times("VCNT2020")
    assert (rise, fall, load, assumed) == (1e-5, 1.5e-5, 100.0, False)
    r2 = catalogue.get_part("VCNT2020").model.load_resistor_ohm
    tau_r, tau_f = time_constants_s(rise, fall, load, r2)
    assert tau_f == pytest.approx(15e-6 / math.log(9) * (r2 / 100) ** 0.7, rel=1e-12)
    assert (tau_r, tau_f) == pytest.approx((107.1e-6, 160.6e-6), rel=1e-3)
    # one conversion at 10 kSa/s: exp(−100/107.1) = 0.393 rising, exp(−100/160.6) = 0.537
    # falling; settled to 0.1 % below 1/(160.6 µs · ln 1000) = 901 Sa/s
    r_r, r_f = residues("multiplexed", 1e4, (tau_r, tau_f))
    assert (r_r, r_f) == pytest.approx((math.exp(-100e-6 / tau_r), math.exp(-100e-6 / tau_f)))
    assert residues("dc", 1e4, (tau_r, tau_f)) == (0.0, 0.0)
    assert settling_rate_hz(tau_f) == pytest.approx(1 / (tau_f * math.log(1000)), rel=1e-12)
    assert residues("modulated", settling_rate_hz(tau_f), (tau_f, tau_f))[1] == pytest.approx(1e-3)
    # a neighbour's light left: r_r (1 − r_f)/(1 − r_r) = 0.393 · 0.463 / 0.607 = 0.300
    assert crosstalk_left(r_r, r_f) == pytest.approx(0.300, abs=1e-3)


def test_the_load_exponent_is_an_assumed_figure_at_its_unfavourable_end():
    assert LOAD_EXPONENT["kind"] == "assumed"
    assert LOAD_EXPONENT["value"] == max(LOAD_EXPONENT["range"])


def test_a_switched_drive_keeps_the_residue_of_the_crosstalk():
    tau = (50e-6, 50e-6)
    r = math.exp(-1e-4 / 50e-6)  # 13.5 % at 10 kSa/s, rising and falling alike
    multiplexed = drive_effects("multiplexed", 2, 1e4, 100.0, tau_s=tau)
    assert multiplexed.crosstalk == pytest.approx(r) and multiplexed.settling_residue == r
    modulated = drive_effects("modulated", 2, 1e4, 100.0, tau_s=tau)
    assert modulated.crosstalk == pytest.approx(r) and modulated.ambient_dc == 0.0
    slow = drive_effects("multiplexed", 2, 100.0, 100.0, tau_s=tau)  # settled
    assert slow.crosstalk < 1e-80
    assert drive_effects("dc", 2, 1e4, 100.0, tau_s=tau).crosstalk == 1.0
    assert drive_effects("multiplexed", 2, 1e4, 100.0).crosstalk == 0.0  # none given: settled


def test_bad_switching_figures_are_refused():
    with pytest.raises(InputError, match="positive and finite"):
        time_constants_s(0.0, 1e-5, 100.0, 1e4)


def test_the_settled_share_and_the_crosstalk_left_by_hand_and_by_simulation():
    """G by hand at r_r = r_f = 0.8, N = 2, and G and the crosstalk left against a
    window-by-window simulation of a detector whose time constant follows the direction it
    moves in (r_r = 0.5 rising, r_f = 0.8 falling), run to its periodic state, with a weak
    light x lit the window before the sensor's own."""
    r = 0.8
    assert settled_share("dc", 2, r, r) == 1.0
    assert settled_share("multiplexed", 2, r, r) == pytest.approx(0.2 / 0.36, rel=1e-14)
    assert settled_share("modulated", 2, r, r) == pytest.approx(0.04 / (1 - 0.8**4), rel=1e-14)
    assert crosstalk_left(r, r) == pytest.approx(r, rel=1e-14)
    r_r, r_f, x = 0.5, 0.8, 1e-3
    for scheme, windows in (("multiplexed", 2), ("modulated", 4)):

        def run(own, neighbour, windows=windows, scheme=scheme):
            y, seen = 0.0, []
            for step in range(4000):
                lit = step % windows == 0
                target = (own if lit else 0.0) + (neighbour if step % windows == windows - 1 else 0)
                keep = r_r if target > y else r_f
                y = target + (y - target) * keep
                seen.append(y)
            on, off = seen[-windows], seen[-windows + 1]
            return on if scheme == "multiplexed" else on - off

        gain = run(1.0, 0.0)
        assert settled_share(scheme, 2, r_r, r_f) == pytest.approx(gain, rel=1e-9)
        left = (run(1.0, x) - gain) / x / gain
        assert crosstalk_left(r_r, r_f) == pytest.approx(left, rel=1e-3)
