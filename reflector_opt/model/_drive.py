"""How the LEDs are driven and read: what each scheme does to crosstalk, ambient light, dark
current, self-heating, sample rate and noise.

Three schemes (docs/conditions.md, "Drive schemes"), for a unit whose N sensors share one
ADC converting at f_s:

``dc``
    Every LED on all the time; the detectors are read in turn. Every detector also sees the
    light of its neighbours' LEDs (crosstalk), the ambient light, and its dark current. Each
    LED dissipates all the time (duty 1). A frame of N readings takes N / f_s.
``multiplexed``
    One LED on at a time, its own detector read while it is on (the reference paper's
    proposal, through a demultiplexer): no LED but the read one is lit, so no crosstalk —
    assuming the demultiplexer spans every LED that can reach the detector, the neighbouring
    units' included. Ambient light and dark current stay. Duty 1/N.
``modulated``
    As multiplexed, and each detector read twice, LED on and LED off, the difference kept
    (synchronous detection at its simplest). Whatever does not follow the LED cancels:
    constant ambient light and the dark current with its temperature drift. Flicker changes
    between the two reads, 1/f_s apart, and leaves a residue of amplitude
    ``A · abs(1 − exp(i 2π f Δt)) = 2A · abs(sin(π f Δt))`` (Δt = 1/f_s). The difference of
    two reads has √2 times the noise of one; a frame takes 2N / f_s; duty 1/(2N).

The switched schemes take a reading one conversion after the LED changed: a detector that has
not settled carries a share r of the LED lit before (:mod:`reflector_opt.model._settling`),
so their "no crosstalk" holds to r only: the crosstalk left is r, and the scheme's frame rate
is honest only below the rate at which the detectors settle (``settling_rate_hz``). Below it,
a reading keeps only ``settled_share`` of its own light, so what does not follow the LED
(ambient light, dark current, noise) weighs 1/share more than for settled detectors.

The figures are the standard account of synchronous detection (e.g. Meade, *Lock-in
Amplifiers: Principles and Applications*, IEE 1983, ch. 1; the differencing residue is the
first difference's transfer function ``abs(1 − z⁻¹)`` on the unit circle).
"""

import math
from dataclasses import dataclass

from reflector_opt.model._settling import (
    crosstalk_left,
    residues,
    settled_share,
    settling_rate_hz,
)
from reflector_opt.util._errors import InputError

DRIVES = ("dc", "multiplexed", "modulated")


@dataclass(frozen=True)
class DriveEffects:
    """What a drive scheme leaves of each disturbance, for one unit.

    Attributes
    ----------
    scheme : str
        ``"dc"``, ``"multiplexed"`` or ``"modulated"``.
    crosstalk : float
        Share of the neighbours' light a detector still sees (1 or 0).
    ambient_dc : float
        Share of a constant ambient change left in the reading (1 or 0).
    flicker : float
        Left share of the flicker's amplitude (1, or the differencing residue).
    dark_current_cancelled : bool
        The reading cancels the dark current and its drift.
    duty : float
        Share of the time each LED is on.
    noise_factor : float
        RMS noise of a reading over that of one ADC conversion.
    frame_rate_hz : float
        Complete readings of the unit (every sensor once) per second.
    settling_residue : float
        Share of the light lit the window before that a reading still carries, relative to its
        own learned response (0 under ``dc``).
    settling_rate_hz : float or None
        The highest sample rate at which the detectors settle to 0.1 % (None: not given).
    settled_share : float
        Share of its own LED's light a reading keeps (1: settled; under ``dc`` always).
    read_interval_s : float
        Time between the readings of two sensors read in turn, s (1/f_s; 2/f_s differenced).
    """

    scheme: str
    crosstalk: float
    ambient_dc: float
    flicker: float
    dark_current_cancelled: bool
    duty: float
    noise_factor: float
    frame_rate_hz: float
    settling_residue: float = 0.0
    settling_rate_hz: float | None = None
    settled_share: float = 1.0
    read_interval_s: float = 0.0

    def to_dict(self):
        """The effects as plain values (the ``--json`` block)."""
        return dict(self.__dict__)


def drive_effects(scheme, n_sensors, sample_rate_hz, flicker_hz, tau_s=None):
    """The effects of a drive scheme on a unit of ``n_sensors`` read at ``sample_rate_hz``.

    Parameters
    ----------
    scheme : str
        ``"dc"``, ``"multiplexed"`` or ``"modulated"``.
    n_sensors : int
        Sensors read in turn by one ADC.
    sample_rate_hz : float
        ADC conversions per second, Hz.
    flicker_hz : float
        Frequency of the ambient flicker, Hz.
    tau_s : (float, float), optional
        The slowest detector's rising and falling time constants at its load, s
        (:func:`~reflector_opt.model._settling.time_constants_s`); None takes the detectors for
        settled.

    Returns
    -------
    DriveEffects
    """
    if scheme not in DRIVES:
        raise InputError(f"drive: expected one of {', '.join(DRIVES)}, got {scheme!r}")
    if not (sample_rate_hz > 0 and math.isfinite(sample_rate_hz)):
        raise InputError(f"sample_rate_hz: must be positive and finite, got {sample_rate_hz}")
    n = int(n_sensors)
    settled = {}
    if tau_s is not None:
        rise, fall = residues(scheme, sample_rate_hz, tau_s)
        settled = {
            "settling_residue": crosstalk_left(rise, fall),
            "settling_rate_hz": settling_rate_hz(max(tau_s)),
            "settled_share": settled_share(scheme, int(n_sensors), rise, fall),
        }
    switched, differenced = scheme != "dc", scheme == "modulated"
    reads = 2 if differenced else 1  # conversions per reading
    flicker = 2.0 * abs(math.sin(math.pi * flicker_hz / sample_rate_hz)) if differenced else 1.0
    return DriveEffects(
        scheme,
        settled.get("settling_residue", 0.0) if switched else 1.0,
        0.0 if differenced else 1.0,
        flicker,
        differenced,
        1.0 / (reads * n) if switched else 1.0,
        math.sqrt(reads),
        sample_rate_hz / (reads * n),
        **settled,
        read_interval_s=reads / sample_rate_hz,
    )
