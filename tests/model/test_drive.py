"""Drive schemes: what each leaves of crosstalk, ambient light and flicker, by hand."""

import math

import pytest

from reflector_opt.model._drive import drive_effects
from reflector_opt.util._errors import InputError


def test_dc_leaves_everything_and_heats_all_the_time():
    e = drive_effects("dc", 2, 10_000.0, 100.0)
    assert (e.crosstalk, e.ambient_dc, e.flicker, e.duty, e.noise_factor) == (1, 1, 1, 1, 1)
    assert not e.dark_current_cancelled
    assert e.frame_rate_hz == 5000.0


def test_multiplexed_removes_crosstalk_only():
    e = drive_effects("multiplexed", 4, 10_000.0, 100.0)
    assert e.crosstalk == 0.0 and e.ambient_dc == 1.0 and e.flicker == 1.0
    assert e.duty == 0.25 and e.frame_rate_hz == 2500.0


def test_modulated_leaves_the_differencing_residue_of_the_flicker():
    e = drive_effects("modulated", 2, 1000.0, 120.0)
    # reads 1 ms apart: |1 − exp(i·2π·120 Hz·1 ms)| = 2 sin(0.12 π) = 0.7362
    assert e.flicker == pytest.approx(2 * math.sin(0.12 * math.pi))
    assert e.flicker == pytest.approx(
        abs(1 - complex(math.cos(0.24 * math.pi), math.sin(0.24 * math.pi)))
    )
    assert e.ambient_dc == 0.0 and e.crosstalk == 0.0 and e.dark_current_cancelled
    assert e.noise_factor == pytest.approx(math.sqrt(2)) and e.duty == 0.25
    assert e.frame_rate_hz == 250.0


def test_unknown_scheme_and_bad_rate_are_refused():
    with pytest.raises(InputError, match="drive"):
        drive_effects("ac", 2, 1000.0, 100.0)
    with pytest.raises(InputError, match="sample_rate_hz"):
        drive_effects("dc", 2, float("nan"), 100.0)
