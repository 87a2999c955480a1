"""The detector's speed under switched drives: how far a reading has settled when it is taken.

A phototransistor answers a step of light as a first-order system (the collector-base
capacitance, multiplied by the gain, charged through the load): its 10-90 % rise time is
t_r = τ · ln 9. Datasheets state t_r and t_f at a test load R_test (often 100 Ω), and the
circuit's load R2 (about 10 kΩ) is slower: τ(R2) = τ(R_test) · (R2 / R_test)^p with p from
the one curve of switching time against load read (:data:`LOAD_EXPONENT`).

Under ``multiplexed`` and ``modulated`` drive each LED is lit for one ADC conversion,
t_w = 1/f_s, before its detector is read (``dc`` keeps every LED on: settled). The reading has
then come (1 − r) of the way, r = exp(−t_w / τ) (:func:`residue`): the detector still carries r
of the light of the LED lit before — a neighbour's included — so the drive's "no crosstalk"
holds to r only (:func:`reflector_opt.model.drive.drive_effects`). Over a frame the detector
reaches, of its own LED's light L, a periodic state: lit for one window of the N (``multiplexed``)
it ends at y = L(1 − r) + r · rᴺ⁻¹ · y, so y = L(1 − r)/(1 − rᴺ); lit for one window of 2N and
read lit and dark (``modulated``), the difference keeps L(1 − r)²/(1 − r²ᴺ)
(:func:`settled_share`). That share of the light is the same at calibration and in use and is
learned, but what does not follow the LED — ambient light, the dark current, the supply at the
collector, the noise — passes whole: each costs the angles 1/share of what it costs a settled
detector. A reading settled to a share s needs t_w ≥ τ · ln(1/s): :func:`settling_rate_hz`.
"""

from __future__ import annotations

import math

from reflector_opt.util.errors import InputError

__all__ = [
    "LOAD_EXPONENT",
    "SETTLED_SHARE",
    "residue",
    "settled_share",
    "settling_rate_hz",
    "time_constant_s",
]

#: Exponent p of the switching time's growth with the load, τ ∝ R_L^p, with kind and source.
LOAD_EXPONENT = {
    "value": 0.7,
    "kind": "assumed",
    "range": [0.3, 0.7],
    "source": "onsemi QRE1113 rev. 2.7, Fig. 7 (switching time vs load resistance, V_CC 10 V), "
    "read off: at I_C 0.3 mA t_r 9 us at 100 ohm, 18 us at 1 kohm, 60-90 us at 10 kohm "
    "(slopes 0.30 and 0.52-0.70 per decade), at 1 mA 3.8 to 11 us (0.46); no other part's "
    "curve was read: 0.7, the unfavourable end",
}
#: The share of a step left when a reading counts as settled (below one LSB of a 10-bit ADC).
SETTLED_SHARE = 1e-3


def time_constant_s(rise_s, fall_s, test_load_ohm, load_ohm, exponent=LOAD_EXPONENT["value"]):
    """The detector's time constant at the circuit's load, s.

    τ = max(t_r, t_f) / ln 9 · (R2 / R_test)^p (module notes).

    Parameters
    ----------
    rise_s, fall_s : float
        10-90 % rise and 90-10 % fall times at the test load, s.
    test_load_ohm, load_ohm : float
        The datasheet's test load and the circuit's, Ω.
    exponent : float, optional
        p.

    Returns
    -------
    float
    """
    values = (rise_s, fall_s, test_load_ohm, load_ohm)
    if not all(math.isfinite(v) and v > 0 for v in values):
        raise InputError(f"switching times and loads must be positive and finite, got {values}")
    return max(rise_s, fall_s) / math.log(9.0) * (load_ohm / test_load_ohm) ** exponent


def residue(scheme, sample_rate_hz, tau_s):
    """The share of the previous state left in a reading: exp(−(1/f_s)/τ), 0 under ``dc``.

    Parameters
    ----------
    scheme : str
        ``"dc"``, ``"multiplexed"`` or ``"modulated"``.
    sample_rate_hz : float
        ADC conversions per second, Hz (one conversion per LED window).
    tau_s : float
        The detector's time constant, s.

    Returns
    -------
    float
    """
    if scheme == "dc":
        return 0.0
    return math.exp(-1.0 / (sample_rate_hz * tau_s))


def settled_share(scheme, n_sensors, left):
    """The share of its own LED's light a reading keeps under a switched drive (module notes).

    ``(1 − r)/(1 − rᴺ)`` under ``multiplexed``, ``(1 − r)²/(1 − r²ᴺ)`` under ``modulated``
    (the lit reading less the dark one), 1 under ``dc``.

    Parameters
    ----------
    scheme : str
        ``"dc"``, ``"multiplexed"`` or ``"modulated"``.
    n_sensors : int
        LEDs lit in turn, N.
    left : float
        The residue r of one window (:func:`residue`), in [0, 1).

    Returns
    -------
    float
    """
    if scheme == "dc" or left == 0.0:
        return 1.0
    if scheme == "multiplexed":
        return (1.0 - left) / (1.0 - left**n_sensors)
    return (1.0 - left) ** 2 / (1.0 - left ** (2 * n_sensors))


def settling_rate_hz(tau_s, share=SETTLED_SHARE):
    """The highest sample rate at which a switched drive's readings settle to ``share``, Hz.

    f_s = 1 / (τ · ln(1/share)).

    Parameters
    ----------
    tau_s : float
        The detector's time constant, s.
    share : float, optional
        The residue allowed, in (0, 1).

    Returns
    -------
    float
    """
    return 1.0 / (tau_s * math.log(1.0 / share))
