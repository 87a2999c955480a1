"""Measurement imperfections of the read-out: noise, ADC quantisation, gain and offset.

Pure, vectorised functions on voltages with sensors along the last axis. The order in
:func:`measure` follows the signal path: the sensor's own gain and offset (component
tolerances, :class:`Mismatch`), then additive electrical noise, then the ADC, which clips
to its input range and rounds to the nearest code (mid-tread quantiser; the rounding error
is uniform within ±LSB/2, RMS LSB/√12, matching
:attr:`reflector_opt.design._components.Noise.total_sigma_v`). Random draws come from a
:class:`numpy.random.Generator` the caller seeds.
"""

from dataclasses import dataclass

import numpy as np

from reflector_opt.util._errors import InputError


def add_noise(volts, sigma_v, rng):
    """Add white Gaussian voltage noise.

    Parameters
    ----------
    volts : array_like
        Noise-free voltages, V, any shape.
    sigma_v : float
        RMS noise, V (0 returns a copy).
    rng : numpy.random.Generator

    Returns
    -------
    numpy.ndarray
        ``volts + N(0, sigma_v²)``, V, same shape.
    """
    volts = np.asarray(volts, dtype=float)
    if sigma_v < 0:
        raise InputError(f"sigma_v: must not be negative, got {sigma_v}")
    if sigma_v == 0:
        return volts.copy()
    return volts + rng.normal(0.0, sigma_v, volts.shape)


def quantise(volts, adc_bits, vref):
    """Convert voltages with an ideal ADC and back: clip to [0, vref − LSB], round to a code.

    Parameters
    ----------
    volts : array_like
        Analogue input, V.
    adc_bits : int
        Resolution, bits; LSB = vref / 2**adc_bits.
    vref : float
        Reference (full-scale) voltage, V.

    Returns
    -------
    numpy.ndarray
        ``code · LSB`` with ``code = clip(round(volts / LSB), 0, 2**adc_bits − 1)``, V.
    """
    if int(adc_bits) != adc_bits or not 1 <= adc_bits <= 32:
        raise InputError(f"adc_bits: must be a whole number from 1 to 32, got {adc_bits}")
    if vref <= 0:
        raise InputError(f"vref: must be positive, got {vref}")
    lsb = vref / 2.0**adc_bits
    codes = np.clip(np.rint(np.asarray(volts, dtype=float) / lsb), 0, 2**adc_bits - 1)
    return codes * lsb


@dataclass(frozen=True)
class Mismatch:
    """Per-sensor gain and offset: ``v' = gain · v + offset_v``.

    Parameters
    ----------
    gain : tuple of float
        Multiplicative gain of each sensor's output (1 = nominal).
    offset_v : tuple of float
        Additive offset of each sensor's output, V.
    """

    gain: tuple[float, ...] = (1.0, 1.0)
    offset_v: tuple[float, ...] = (0.0, 0.0)

    def __post_init__(self):
        if len(self.gain) != len(self.offset_v):
            raise InputError(
                f"mismatch: {len(self.gain)} gains but {len(self.offset_v)} offsets; "
                "give one of each per sensor"
            )
        if not np.all(np.isfinite(self.gain)) or not np.all(np.isfinite(self.offset_v)):
            raise InputError("mismatch: gains and offsets must be finite")

    @classmethod
    def draw(cls, rng, n_sensors=2, gain_sigma=0.02, offset_sigma_v=0.02):
        """Random mismatch: gain ~ N(1, gain_sigma²), offset ~ N(0, offset_sigma_v²).

        Parameters
        ----------
        rng : numpy.random.Generator
        n_sensors : int
        gain_sigma : float
            Relative standard deviation of the gain (0.02 = 2 %).
        offset_sigma_v : float
            Standard deviation of the offset, V.

        Returns
        -------
        Mismatch
        """
        gain = 1.0 + gain_sigma * rng.standard_normal(n_sensors)
        offset = offset_sigma_v * rng.standard_normal(n_sensors)
        return cls(tuple(gain.tolist()), tuple(offset.tolist()))

    def apply(self, volts):
        """Apply to voltages with sensors on the last axis, V -> V."""
        volts = np.asarray(volts, dtype=float)
        if volts.shape[-1] != len(self.gain):
            raise InputError(
                f"mismatch: defined for {len(self.gain)} sensors, voltages have {volts.shape[-1]}"
            )
        return np.asarray(self.gain) * volts + np.asarray(self.offset_v)


def measure(volts, rng, *, sigma_v=0.0, adc_bits=None, vref=3.3, mismatch=None):
    """What a data logger records from noise-free sensor voltages.

    Parameters
    ----------
    volts : array_like
        Noise-free sensor output, V, sensors on the last axis.
    rng : numpy.random.Generator
        Source of the noise.
    sigma_v : float
        Additive RMS noise, V.
    adc_bits : int or None
        ADC resolution, bits; None skips quantisation.
    vref : float
        ADC reference voltage, V.
    mismatch : Mismatch or None
        Per-sensor gain and offset applied first.

    Returns
    -------
    numpy.ndarray
        Recorded voltages, V, same shape.
    """
    if mismatch is not None:
        volts = mismatch.apply(volts)
    volts = add_noise(volts, sigma_v, rng)
    if adc_bits is not None:
        volts = quantise(volts, adc_bits, vref)
    return volts
