"""The sensor's circuit: from optical coupling to output voltage, and back.

The paper's Fig. 2f (docs/model.md §3 "Electronics"): the LED is driven from the supply
through R1, the phototransistor's collector through the load R2, and the output is the
collector voltage::

    I_F   = (Vcc − V_F) / R1
    I_C   = G · I_F · η + I_dark
    V_out = clip(Vcc − I_C · R2, V_CE(sat), Vcc)

so more light gives a *lower* voltage (the inversion of the paper's Fig. 8). What changes in
use (temperature, the supply and the ADC reference, stray light) is applied by the voltage
pipeline, :mod:`reflector_opt.model._operating`. G lumps the
LED's efficiency, the phototransistor's responsivity and its gain into one collector current
per LED current per unit coupling η (detected over emitted optical power).

Pure, vectorised functions of the circuit values;
:class:`~reflector_opt.model._sensors.SensorModel` calls them with its own parameters.
"""

import numpy as np

#: How an ADC reads the outputs: against its own fixed reference, or as a share of the supply.
ADC_REFERENCES = ("fixed", "ratiometric")


def led_current(supply_v, led_forward_v, led_resistor_ohm):
    """LED forward current I_F = (Vcc − V_F) / R1 (paper Fig. 2f).

    Parameters
    ----------
    supply_v : float or array_like
        Supply voltage Vcc, V.
    led_forward_v : float or array_like
        LED forward voltage V_F, V.
    led_resistor_ohm : float or array_like
        LED series resistor R1, Ω.

    Returns
    -------
    float or numpy.ndarray
        I_F, A.
    """
    return (supply_v - led_forward_v) / led_resistor_ohm


def collector_current(coupling, *, current_gain, led_current_a, dark_current_a=0.0):
    """Phototransistor collector current I_C = G · I_F · η + I_dark, before saturation.

    Parameters
    ----------
    coupling : array_like
        Detected over emitted optical power η (dimensionless).
    current_gain : float
        Lumped gain G = I_C / (I_F · η) (dimensionless).
    led_current_a : float
        LED forward current I_F, A (:func:`led_current`).
    dark_current_a : float, optional
        Collector current with no light (dark current plus ambient), A.

    Returns
    -------
    numpy.ndarray
        I_C, A, shape of ``coupling``.
    """
    return current_gain * led_current_a * np.asarray(coupling) + dark_current_a


def output_voltage(collector_current_a, *, supply_v, load_resistor_ohm, saturation_v):
    """Output voltage V_out = Vcc − I_C · R2, clamped to [V_CE(sat), Vcc].

    Parameters
    ----------
    collector_current_a : array_like
        Collector current I_C, A (:func:`collector_current`).
    supply_v : float
        Supply voltage Vcc, V.
    load_resistor_ohm : float
        Collector load R2, Ω.
    saturation_v : float
        Collector–emitter saturation voltage V_CE(sat), V: the lowest output.

    Returns
    -------
    numpy.ndarray
        V_out, V. It falls as the light rises.
    """
    v = supply_v - np.asarray(collector_current_a) * load_resistor_ohm
    return np.clip(v, saturation_v, supply_v)


def coupling_from_voltage(
    volts, *, current_gain, led_current_a, supply_v, load_resistor_ohm, dark_current_a=0.0
):
    """Coupling η that gives an output voltage: :func:`output_voltage` inverted, unclamped.

    ``I_C = (Vcc − V_out) / R2`` and ``η = (I_C − I_dark) / (G · I_F)``. Exact where the
    output is not clamped; a clamped voltage gives the η at the clamp's edge or beyond it.

    Parameters
    ----------
    volts : array_like
        Output voltage V_out, V.
    current_gain : float
        Lumped gain G (dimensionless).
    led_current_a : float
        LED forward current I_F, A.
    supply_v : float
        Supply voltage Vcc, V.
    load_resistor_ohm : float
        Collector load R2, Ω.
    dark_current_a : float, optional
        Collector current with no light, A.

    Returns
    -------
    numpy.ndarray
        η (dimensionless), shape of ``volts``.
    """
    current = (supply_v - np.asarray(volts, dtype=float)) / load_resistor_ohm
    return (current - dark_current_a) / (current_gain * led_current_a)
