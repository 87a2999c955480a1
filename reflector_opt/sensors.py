"""Reflective optoelectronic sensors: optical parameters, presets and the electronics.

A :class:`SensorModel` holds what the optics needs (emitter size and beam divergence, the
emitter–detector offset, the detector area) and what the electronics needs (supply, the LED
resistor R1, the phototransistor load R2, saturation voltage and a lumped current gain), plus
the usable distance range. The circuit is the paper's Fig. 2f: the LED is driven through R1,
the phototransistor's collector through R2, and the output is the collector voltage, so more
light gives a *lower* voltage (the inversion the paper reports in its Fig. 8).

Datasheets do not give the optical parameters; the presets' values are documented
assumptions (docs/model.md) chosen so that a flat reflector gives the datasheet's response
shape: a peak just below the near end of the usable range and a monotonic fall of light
(rise of voltage) across it. Replace them with a measured curve
(:func:`reflector_opt.measured.fit_sensor_model`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np

from reflector_opt.errors import InputError

__all__ = ["PRESETS", "SensorModel", "get_preset"]


@dataclass(frozen=True)
class SensorModel:
    """Optical and electrical parameters of one reflective sensor type.

    Parameters
    ----------
    name : str
        Part name, e.g. ``"NJL5901R-2"``.
    range_mm : tuple of float
        Usable (min, max) sensor-to-reflector distance, mm.
    emitter_detector_mm : float
        Distance |e| from the LED centre to the phototransistor centre, mm.
    source_radius_mm : float
        1/e radius ω0 of the LED's emitting area, mm.
    divergence_deg : float
        1/e half-angle θ of the emitted beam, degrees.
    detector_area_mm2 : float
        Phototransistor light-sensitive area S_area, mm².
    supply_v : float
        Supply voltage Vcc, V.
    led_forward_v : float
        LED forward voltage V_F, V.
    led_resistor_ohm : float
        LED series resistor R1, Ω.
    load_resistor_ohm : float
        Phototransistor collector load R2, Ω.
    saturation_v : float
        Collector–emitter saturation voltage V_CE(sat), V: the lowest output.
    current_gain : float
        Collector current per LED current per unit optical coupling, I_C / (I_F · η)
        (dimensionless, lumps LED efficiency, responsivity and transistor gain).
    dark_current_a : float
        Collector current with no light (dark current plus ambient), A.
    """

    name: str
    range_mm: tuple[float, float]
    emitter_detector_mm: float
    source_radius_mm: float
    divergence_deg: float
    detector_area_mm2: float
    supply_v: float
    led_forward_v: float
    led_resistor_ohm: float
    load_resistor_ohm: float
    saturation_v: float
    current_gain: float
    dark_current_a: float = 0.0

    def __post_init__(self):
        positive = (
            "emitter_detector_mm",
            "source_radius_mm",
            "detector_area_mm2",
            "supply_v",
            "led_resistor_ohm",
            "load_resistor_ohm",
            "current_gain",
        )
        for field in positive:
            value = getattr(self, field)
            if not np.isfinite(value) or value <= 0:
                raise InputError(f"sensor {self.name!r}: {field} must be positive, got {value}")
        if not 0.0 < self.divergence_deg < 90.0:
            raise InputError(f"sensor {self.name!r}: divergence_deg must be in (0, 90)")
        lo, hi = self.range_mm
        if not 0.0 <= lo < hi:
            raise InputError(f"sensor {self.name!r}: range_mm must satisfy 0 <= min < max")
        if self.led_forward_v >= self.supply_v:
            raise InputError(f"sensor {self.name!r}: led_forward_v must be below supply_v")
        if not 0.0 <= self.saturation_v < self.supply_v:
            raise InputError(f"sensor {self.name!r}: saturation_v must be in [0, supply_v)")

    @property
    def led_current_a(self):
        """LED forward current I_F = (Vcc − V_F) / R1, A."""
        return (self.supply_v - self.led_forward_v) / self.led_resistor_ohm

    def collector_current(self, coupling):
        """Phototransistor current I_C = G · I_F · η + I_dark, A.

        Parameters
        ----------
        coupling : array_like
            Detected over emitted optical power η (dimensionless).

        Returns
        -------
        numpy.ndarray
            Collector current before saturation, A.
        """
        return self.current_gain * self.led_current_a * np.asarray(coupling) + self.dark_current_a

    def output_voltage(self, coupling):
        """Output voltage V_out = Vcc − I_C · R2, clamped to [V_CE(sat), Vcc].

        Parameters
        ----------
        coupling : array_like
            Detected over emitted optical power η (dimensionless).

        Returns
        -------
        numpy.ndarray
            Output voltage, V. It falls as the light rises.
        """
        v = self.supply_v - self.collector_current(coupling) * self.load_resistor_ohm
        return np.clip(v, self.saturation_v, self.supply_v)

    def coupling_from_voltage(self, volts):
        """Invert :meth:`output_voltage` where it is not clamped.

        Parameters
        ----------
        volts : array_like
            Output voltage, V.

        Returns
        -------
        numpy.ndarray
            Coupling η (dimensionless) that produces ``volts``.
        """
        current = (self.supply_v - np.asarray(volts, dtype=float)) / self.load_resistor_ohm
        return (current - self.dark_current_a) / (self.current_gain * self.led_current_a)

    def with_(self, **changes):
        """Return a copy with some parameters replaced (validated again)."""
        return replace(self, **changes)

    def to_dict(self):
        """Parameters as a JSON-ready dict."""
        d = asdict(self)
        d["range_mm"] = list(self.range_mm)
        return d

    @classmethod
    def from_dict(cls, data):
        """Build from :meth:`to_dict` output; unknown or missing keys are an InputError."""
        fields = set(cls.__dataclass_fields__)
        unknown = set(data) - fields
        if unknown:
            raise InputError(f"sensor model: unknown key(s) {sorted(unknown)}")
        required = {
            f for f, v in cls.__dataclass_fields__.items() if v.default is v.default_factory
        }
        missing = {"name", *required} - set(data) - {"dark_current_a"}
        if missing:
            raise InputError(f"sensor model: missing key(s) {sorted(missing)}")
        values = dict(data)
        values["range_mm"] = tuple(float(x) for x in values["range_mm"])
        return cls(**values)


#: NJL5901R-2 (New Japan Radio), the paper's part: 1.0 × 1.4 × 0.6 mm, usable 0.5–3 mm,
#: R1 = 680 Ω and R2 = 10 kΩ as in the paper. Supply 3.3 V (the ADC reference), V_F = 1.2 V
#: (typical for an IR LED at a few mA). Optical values are assumptions: an LED die of
#: 0.15 mm, a 1/e half-angle of 30.8°, LED–detector spacing 0.5 mm and a 0.3 × 0.3 mm
#: detector put the flat-mirror peak at 0.40 mm; the current gain puts that peak at about
#: 0.4 V, near saturation, as on the datasheet curve.
NJL5901R_2 = SensorModel(
    name="NJL5901R-2",
    range_mm=(0.5, 3.0),
    emitter_detector_mm=0.5,
    source_radius_mm=0.15,
    divergence_deg=30.8,
    detector_area_mm2=0.09,
    supply_v=3.3,
    led_forward_v=1.2,
    led_resistor_ohm=680.0,
    load_resistor_ohm=10_000.0,
    saturation_v=0.2,
    current_gain=2.4,
)

#: A longer-range part for comparison, in the spirit of the QRE1113 the authors used before
#: (usable 2–10 mm). All optical and gain values are assumptions giving a flat-mirror peak
#: near 1.6 mm; 5 V supply, R1 = 330 Ω, R2 = 10 kΩ.
QRE1113 = SensorModel(
    name="QRE1113",
    range_mm=(2.0, 10.0),
    emitter_detector_mm=1.8,
    source_radius_mm=0.3,
    divergence_deg=29.0,
    detector_area_mm2=0.5,
    supply_v=5.0,
    led_forward_v=1.2,
    led_resistor_ohm=330.0,
    load_resistor_ohm=10_000.0,
    saturation_v=0.2,
    current_gain=2.4,
)

PRESETS = {m.name: m for m in (NJL5901R_2, QRE1113)}


def get_preset(name):
    """Look up a sensor preset by part name.

    Parameters
    ----------
    name : str
        One of ``PRESETS`` (``"NJL5901R-2"``, ``"QRE1113"``).

    Returns
    -------
    SensorModel
    """
    try:
        return PRESETS[name]
    except KeyError:
        raise InputError(
            f"unknown sensor preset {name!r}; known presets: {', '.join(sorted(PRESETS))}"
        ) from None
