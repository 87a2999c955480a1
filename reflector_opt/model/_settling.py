"""The detector's speed under switched drives: how far a reading has settled when it is taken.

A phototransistor answers a step of light as a first-order system (the collector-base
capacitance, multiplied by the gain, charged through the load): its 10-90 % rise time is
t_r = τ_r · ln 9, its fall time t_f = τ_f · ln 9, the time constant by the direction the output
moves. Datasheets state t_r and t_f at a test load R_test (often 100 Ω), and the circuit's load
R2 (about 10 kΩ) is slower: τ(R2) = τ(R_test) · (R2 / R_test)^p with p from the one curve of
switching time against load read (:data:`LOAD_EXPONENT`).

Under ``multiplexed`` and ``modulated`` drive each LED is lit for one ADC conversion,
t_w = 1/f_s, before its detector is read (``dc`` keeps every LED on: settled). Over one window a
detector keeps r_r = exp(−t_w/τ_r) of its past while its own LED lights it and r_f =
exp(−t_w/τ_f) while it is dark (:func:`residues`). Over a frame it reaches a periodic state:
lit for one window of the N (``multiplexed``) a reading keeps
G = (1 − r_r)/(1 − r_r·r_fᴺ⁻¹) of its own LED's light, lit and read dark in the next window of
2N (``modulated``) the difference keeps G = (1 − r_r)(1 − r_f)/(1 − r_r·r_f²ᴺ⁻¹)
(:func:`settled_share`). That share is the same at calibration and in use and is learned, but
what does not follow the LED — ambient light, the dark current, the supply at the collector,
the noise — passes whole: each costs the angles 1/G of what it costs a settled detector. A
light lit the window before (a neighbour's LED), met while dark and then left as the detector
rises, stays in the reading at r_r·(1 − r_f)/(1 − r_r) of the learned response
(:func:`crosstalk_left`; r for r_r = r_f = r), so the drive's "no crosstalk" holds to that
share only (:func:`reflector_opt.model._drive.drive_effects`). A reading settled to a share s
needs t_w ≥ τ · ln(1/s) for the slower τ: :func:`settling_rate_hz`.
"""

import math

from reflector_opt.util._errors import InputError

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


def time_constants_s(rise_s, fall_s, test_load_ohm, load_ohm, exponent=LOAD_EXPONENT["value"]):
    """The detector's rising and falling time constants at the circuit's load, s.

    τ = t / ln 9 · (R2 / R_test)^p for t = t_r and t_f (module notes).

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
    (float, float)
        τ_r, τ_f.
    """
    values = (rise_s, fall_s, test_load_ohm, load_ohm)
    if not all(math.isfinite(v) and v > 0 for v in values):
        raise InputError(f"switching times and loads must be positive and finite, got {values}")
    scale = (load_ohm / test_load_ohm) ** exponent / math.log(9.0)
    return rise_s * scale, fall_s * scale


def residues(scheme, sample_rate_hz, taus_s):
    """What a detector keeps of its past over one window, rising and falling: (r_r, r_f).

    r = exp(−(1/f_s)/τ); (0, 0) under ``dc`` (settled).

    Parameters
    ----------
    scheme : str
        ``"dc"``, ``"multiplexed"`` or ``"modulated"``.
    sample_rate_hz : float
        ADC conversions per second, Hz (one conversion per LED window).
    taus_s : (float, float)
        τ_r and τ_f, s (:func:`time_constants_s`).

    Returns
    -------
    (float, float)
    """
    if scheme == "dc":
        return 0.0, 0.0
    return tuple(math.exp(-1.0 / (sample_rate_hz * tau)) for tau in taus_s)


def crosstalk_left(r_rise, r_fall):
    """The share of a light lit the window before that a reading keeps, relative to its own
    learned response: r_r · (1 − r_f) / (1 − r_r) (module notes; 0 when settled).

    Parameters
    ----------
    r_rise, r_fall : float
        :func:`residues`, in [0, 1).

    Returns
    -------
    float
    """
    return r_rise * (1.0 - r_fall) / (1.0 - r_rise)


def settled_share(scheme, n_sensors, r_rise, r_fall):
    """The share of its own LED's light a reading keeps under a switched drive (module notes).

    ``(1 − r_r)/(1 − r_r·r_fᴺ⁻¹)`` under ``multiplexed``, ``(1 − r_r)(1 − r_f)/(1 − r_r·r_f²ᴺ⁻¹)``
    under ``modulated`` (the lit reading less the dark one), 1 under ``dc``.

    Parameters
    ----------
    scheme : str
        ``"dc"``, ``"multiplexed"`` or ``"modulated"``.
    n_sensors : int
        LEDs lit in turn, N.
    r_rise, r_fall : float
        :func:`residues`, in [0, 1).

    Returns
    -------
    float
    """
    if scheme == "dc" or (r_rise == 0.0 and r_fall == 0.0):
        return 1.0
    if scheme == "multiplexed":
        return (1.0 - r_rise) / (1.0 - r_rise * r_fall ** (n_sensors - 1))
    return (1.0 - r_rise) * (1.0 - r_fall) / (1.0 - r_rise * r_fall ** (2 * n_sensors - 1))


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
