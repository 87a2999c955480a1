"""The settling term of the voltage pipeline: the photocurrent's settled share, by hand."""

import numpy as np
from numpy.testing import assert_allclose

from reflector_opt.model._operating import OperatingState, apply_state
from reflector_opt.model._sensors import NJL5901R_2


def test_only_the_photocurrent_is_scaled_not_what_does_not_follow_the_led():
    # V = 2.0 V: R2 · I_photo = 1.3 V less the dark part; half settled keeps half of it, and an
    # ambient drop of 10 mV passes whole on top
    m = NJL5901R_2
    photo = 3.3 - 2.0 - m.load_resistor_ohm * m.dark_current_a
    half = apply_state(np.array([[2.0]]), (m,), OperatingState(settled_share=0.5))
    assert_allclose(half, 2.0 + 0.5 * photo, rtol=1e-14)
    both = apply_state(np.array([[2.0]]), (m,), OperatingState(settled_share=0.5, ambient_v=0.01))
    assert_allclose(both, 2.0 + 0.5 * photo - 0.01, rtol=1e-14)
