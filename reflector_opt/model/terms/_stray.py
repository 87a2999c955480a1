"""Light on a detector that is not its own LED's: ambient light and crosstalk.

Each adds collector current I, lowering the output by R2 · I, given here directly as that
drop at the output, V: ``ambient_v`` for room light not present at calibration (≥ 0),
``crosstalk_v`` for the change since calibration of another LED's light (signed: a
neighbour's light can fall as well as rise), ``flicker_v`` for the mains flicker's drop at the
instant each output is read (signed about the light's mean).
"""

from dataclasses import replace

import numpy as np

FIELDS = ("ambient_v", "crosstalk_v", "flicker_v")


def apply(circuit, model, state):
    """The circuit with the stray light's drop of the output added."""
    drop = (
        np.asarray(state["ambient_v"], dtype=float)
        + np.asarray(state["crosstalk_v"])
        + np.asarray(state["flicker_v"])
    )
    if not drop.any():
        return circuit
    return replace(circuit, added_v=circuit.added_v + drop)
