"""The detector's settling under switched drives, by hand."""

import math

import pytest

from reflector_opt.model import catalogue
from reflector_opt.model.drive import drive_effects
from reflector_opt.model.settling import (
    LOAD_EXPONENT,
    residue,
    settled_share,
    settling_rate_hz,
    time_constant_s,
)
from reflector_opt.util.errors import InputError


def test_the_vcnt2020_s_time_constant_at_its_load_by_hand():
    # t_f 15 µs at 100 Ω (Vishay doc 84285): τ = 15 µs / ln 9 = 6.827 µs at 100 Ω; at the
    # circuit's 9108 Ω, × (9108/100)^0.7 = 23.53: 160.6 µs
    rise, fall, load, assumed = catalogue.switching_times("VCNT2020")
    assert (rise, fall, load, assumed) == (1e-5, 1.5e-5, 100.0, False)
    r2 = catalogue.get_part("VCNT2020").model.load_resistor_ohm
    tau = time_constant_s(rise, fall, load, r2)
    assert tau == pytest.approx(15e-6 / math.log(9) * (r2 / 100) ** 0.7, rel=1e-12)
    assert tau == pytest.approx(160.6e-6, rel=1e-3)
    # one conversion at 10 kSa/s: exp(−100/160.6) = 0.537 left; settled to 0.1 % below
    # 1/(160.6 µs · ln 1000) = 901 Sa/s
    assert residue("multiplexed", 1e4, tau) == pytest.approx(math.exp(-100e-6 / tau))
    assert residue("dc", 1e4, tau) == 0.0
    assert settling_rate_hz(tau) == pytest.approx(1 / (tau * math.log(1000)), rel=1e-12)
    assert residue("modulated", settling_rate_hz(tau), tau) == pytest.approx(1e-3)


def test_the_load_exponent_is_an_assumed_figure_at_its_unfavourable_end():
    assert LOAD_EXPONENT["kind"] == "assumed"
    assert LOAD_EXPONENT["value"] == max(LOAD_EXPONENT["range"])


def test_a_switched_drive_keeps_the_residue_of_the_crosstalk():
    tau = 50e-6
    r = math.exp(-1e-4 / tau)  # 13.5 % at 10 kSa/s
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
        time_constant_s(0.0, 1e-5, 100.0, 1e4)


def test_the_settled_share_by_hand_and_by_simulation():
    """(1 − r)/(1 − rᴺ) and (1 − r)²/(1 − r²ᴺ) by hand at r = 0.8, N = 2, and against a
    window-by-window simulation of a first-order detector run to its periodic state."""
    r = 0.8
    assert settled_share("dc", 2, r) == 1.0
    assert settled_share("multiplexed", 2, r) == pytest.approx(0.2 / 0.36, rel=1e-14)
    assert settled_share("modulated", 2, r) == pytest.approx(0.04 / (1 - 0.8**4), rel=1e-14)
    for scheme, windows in (("multiplexed", 2), ("modulated", 4)):
        y, lit = 0.0, []
        for step in range(2000):  # light 1 in the first window of each frame, then dark
            light = 1.0 if step % windows == 0 else 0.0
            y = light + (y - light) * r
            lit.append(y)
        on, off = lit[-windows], lit[-windows + 1]  # the frame's lit and next readings
        read = on if scheme == "multiplexed" else on - off
        assert settled_share(scheme, 2, r) == pytest.approx(read, rel=1e-12)
