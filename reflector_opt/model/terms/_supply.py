"""A change δ of the supply since calibration, and the ADC reference it is read against.

The circuit's I_F = (Vcc − V_F)/R1 (paper Fig. 2f) scales the photocurrent by
1 + δ / (Vcc − V_F) (V_F held), the output rises with Vcc + δ, and a ratiometric ADC, whose
reference is the supply, reads V · Vcc / (Vcc + δ) in the volts of the calibration; a fixed
reference reads V. Exact for the circuit, so

    V' = V + δ − R2 · I_photo · δ / (Vcc − V_F)         (fixed reference)
"""

from dataclasses import replace

FIELDS = ("supply_change_v", "adc_reference")


def apply(circuit, model, state):
    """The circuit with the supply moved by ``state["supply_change_v"]``, V."""
    delta = float(state["supply_change_v"])
    if delta == 0.0:
        return circuit
    headroom = model.supply_v - model.led_forward_v
    scale = model.supply_v / (model.supply_v + delta)
    return replace(
        circuit,
        photo_v=circuit.photo_v * (1.0 + delta / headroom),
        supply_v=circuit.supply_v + delta,
        read_scale=circuit.read_scale * (scale if state["adc_reference"] == "ratiometric" else 1.0),
    )
