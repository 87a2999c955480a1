"""The share of its own LED's light a detector has settled to when a switched drive reads it.

``settled_share`` s (:func:`reflector_opt.model._settling.settled_share`) multiplies the
photocurrent; ambient light, the dark current and the supply at the collector pass whole. It
is the drive's, the same at calibration and in use: the error budget reads its grid of
outputs with it, so that a change of what does not follow the LED weighs 1/s more.
"""

from dataclasses import replace

FIELDS = ("settled_share",)


def apply(circuit, model, state):
    """The circuit with the photocurrent times ``state["settled_share"]``."""
    share = float(state["settled_share"])
    if share == 1.0:
        return circuit
    return replace(circuit, photo_v=circuit.photo_v * share)
