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
(:func:`reflector_opt.model.measured.fit_sensor_model`).
"""

from __future__ import annotations

from dataclasses import MISSING, asdict, dataclass, replace

import numpy as np
from scipy.interpolate import PchipInterpolator

from reflector_opt.model.optics import beam_radius, gaussian_power
from reflector_opt.util.errors import InputError

__all__ = ["PRESETS", "MeasuredCurve", "SensorModel", "get_preset"]


@dataclass(frozen=True)
class MeasuredCurve:
    """A measured output-voltage-versus-distance curve against a flat target.

    Parameters
    ----------
    distance_mm : tuple of float
        Distances to the flat target, strictly increasing, mm.
    volts : tuple of float
        Output voltage at each distance, V.
    reflectance : float
        Reflectance of the target used for the measurement (0–1).
    """

    distance_mm: tuple[float, ...]
    volts: tuple[float, ...]
    reflectance: float = 0.9

    def __post_init__(self):
        d, v = np.asarray(self.distance_mm, float), np.asarray(self.volts, float)
        if d.ndim != 1 or d.shape != v.shape or d.size < 4:
            raise InputError("measured curve: needs at least 4 (distance_mm, volts) points")
        if not (np.all(np.isfinite(d)) and np.all(np.isfinite(v))):
            raise InputError("measured curve: distances and volts must be finite numbers")
        if np.any(np.diff(d) <= 0):
            raise InputError("measured curve: distance_mm must be strictly increasing")
        if not 0 < self.reflectance <= 1:
            raise InputError("measured curve: reflectance must be in (0, 1]")

    def to_dict(self):
        """JSON-ready dict."""
        return {
            "distance_mm": list(self.distance_mm),
            "volts": list(self.volts),
            "reflectance": self.reflectance,
        }


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
        Distance ‖e‖ from the LED centre to the phototransistor centre, mm.
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
    measured_curve : MeasuredCurve, optional
        A measured flat-target curve. When present, the modelled coupling is scaled by the
        measured-over-modelled flat-target coupling at the same distance (interpolated
        monotonically, PCHIP), so the model reproduces the measurement on a flat target and
        keeps its own account of curvature and tilt (:meth:`flat_correction`).
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
    measured_curve: MeasuredCurve | None = None

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

    def flat_coupling(self, distance_mm, reflectance=1.0):
        """Modelled coupling against a flat target at normal incidence (paper Eq 4 with offset).

        Parameters
        ----------
        distance_mm : array_like
            Distance to the flat target, mm.
        reflectance : float, optional
            Target reflectance (0–1).

        Returns
        -------
        numpy.ndarray
            Detected over emitted power (dimensionless).
        """
        w = beam_radius(distance_mm, self.source_radius_mm, self.divergence_deg)
        return gaussian_power(reflectance, self.detector_area_mm2, w, self.emitter_detector_mm)

    def flat_correction(self, distance_mm):
        """Measured over modelled flat-target coupling at each distance; 1 without a curve.

        The ratio at the measured points is interpolated between them with a monotone
        (PCHIP) interpolant. Points clamped at saturation or at the supply carry no coupling
        and are left out; beyond the measured distances the nearest point's ratio is used.

        Parameters
        ----------
        distance_mm : array_like
            Distance along the optical axis, mm (NaN stays NaN).

        Returns
        -------
        numpy.ndarray or float
        """
        curve = self.measured_curve
        if curve is None:
            return 1.0
        d, v = np.asarray(curve.distance_mm, dtype=float), np.asarray(curve.volts, dtype=float)
        unclamped = (v > self.saturation_v) & (v < self.supply_v)  # clamped points carry no η
        d = d[unclamped]
        ratio = self.coupling_from_voltage(v[unclamped]) / self.flat_coupling(d, curve.reflectance)
        return PchipInterpolator(d, ratio)(np.clip(distance_mm, d[0], d[-1]))

    def with_(self, **changes):
        """Return a copy with some parameters replaced (validated again)."""
        return replace(self, **changes)

    def to_dict(self):
        """Parameters as a JSON-ready dict."""
        d = asdict(self)
        d["range_mm"] = list(self.range_mm)
        if self.measured_curve is None:
            del d["measured_curve"]
        else:
            d["measured_curve"] = self.measured_curve.to_dict()
        return d

    @classmethod
    def from_dict(cls, data, where="sensor model"):
        """Build from :meth:`to_dict` output; a bad, unknown or missing key is an InputError."""
        if not isinstance(data, dict):
            raise InputError(f"{where}: expected an object")
        fields = cls.__dataclass_fields__
        unknown = sorted(set(data) - set(fields))
        if unknown:
            raise InputError(f"{where}: unknown key(s) {', '.join(unknown)}")
        required = {
            k for k, f in fields.items() if f.default is MISSING and f.default_factory is MISSING
        }
        missing = sorted(required - set(data))
        if missing:
            raise InputError(f"{where}: missing key(s) {', '.join(missing)}")
        values = {}
        for key, value in data.items():
            if key == "name":
                values[key] = str(value)
            elif key == "range_mm":
                values[key] = _numbers(value, f"{where}.range_mm", 2)
            elif key == "measured_curve":
                values[key] = _curve(value, f"{where}.measured_curve")
            else:
                values[key] = _numbers([value], f"{where}.{key}", 1)[0]
        return cls(**values)


def _numbers(values, where, length):
    if not isinstance(values, list | tuple) or len(values) != length:
        raise InputError(f"{where}: expected {length} number(s)")
    if any(isinstance(v, bool) or not isinstance(v, int | float) for v in values):
        raise InputError(f"{where}: expected numbers, got {values!r}")
    return tuple(float(v) for v in values)


def _curve(value, where):
    if not isinstance(value, dict) or {"distance_mm", "volts"} - set(value):
        raise InputError(f"{where}: expected an object with distance_mm and volts")
    d, v = value["distance_mm"], value["volts"]
    return MeasuredCurve(
        distance_mm=_numbers(d, f"{where}.distance_mm", len(d) if isinstance(d, list) else -1),
        volts=_numbers(v, f"{where}.volts", len(v) if isinstance(v, list) else -1),
        reflectance=_numbers([value.get("reflectance", 0.9)], f"{where}.reflectance", 1)[0],
    )


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
