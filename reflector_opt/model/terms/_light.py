"""A relative change of the light a sensor's own LED puts on its detector.

``light_change`` c multiplies the photocurrent by 1 + c: an LED's output lost to ageing
(c < 0), a drift of the light path common to its LED, the reflector and the detector, or
what a temperature compensation leaves of a curved response.
"""

from dataclasses import replace

import numpy as np

FIELDS = ("light_change",)


def apply(circuit, model, state):
    """The circuit with the photocurrent times 1 + ``state["light_change"]``."""
    change = np.asarray(state["light_change"], dtype=float)
    if not change.any():
        return circuit
    return replace(circuit, photo_v=circuit.photo_v * (1.0 + change))
