"""The junctions' temperature change since calibration (:mod:`reflector_opt.model._temperature`).

The photocurrent is multiplied by :func:`~reflector_opt.model._temperature.photocurrent_factor`
(the LED's output, the detector's gain, the published relative-output curve where there is
one, and the drive current as V_F moves), and the dark current grows by
:func:`~reflector_opt.model._temperature.dark_current_a` at ΔT less its value at calibration,
unless the read-out cancels it (LED on/off differencing).
"""

from dataclasses import replace

import numpy as np

from reflector_opt.model._temperature import dark_current_a, photocurrent_factor

FIELDS = ("delta_t_k", "thermal", "dark_current_changes")


def apply(circuit, model, state):
    """The circuit at the junction temperature change ``state["delta_t_k"]``, K."""
    dt = np.asarray(state["delta_t_k"], dtype=float)
    if not dt.any():
        return circuit
    thermal = state["thermal"]
    growth = 0.0
    if state["dark_current_changes"]:
        growth = dark_current_a(dt, thermal) - dark_current_a(0.0, thermal)
    return replace(
        circuit,
        photo_v=circuit.photo_v * photocurrent_factor(dt, thermal, model),
        added_v=circuit.added_v + model.load_resistor_ohm * growth,
    )
