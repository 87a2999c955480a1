"""Reflective optoelectronic sensors: their parameters and the presets.

A :class:`SensorModel` holds what the optics needs (emitter size and beam divergence, the
emitter–detector offset, the detector area) and what the electronics needs (supply, the LED
resistor R1, the phototransistor load R2, saturation voltage and a lumped current gain), plus
the usable distance range. Its methods put them to use through pure functions: the circuit
of the paper's Fig. 2f, in which more light gives a *lower* voltage
(:mod:`reflector_opt.model._electronics`); the coupling against a flat target and its
correction to a measured curve (:mod:`reflector_opt.model._flat_target`); the checks on its
values and the dict ``design.json`` stores (:mod:`reflector_opt.model._sensor_file`).

Datasheets do not give the optical parameters; the presets' values are documented
assumptions (docs/model.md) chosen so that a flat reflector gives the datasheet's response
shape: a peak just below the near end of the usable range and a monotonic fall of light
(rise of voltage) across it. Replace them with a measured curve
(:func:`reflector_opt.model._measured.fit_sensor_model`).
"""

from dataclasses import dataclass, replace

import numpy as np

from reflector_opt.model import _electronics as electronics
from reflector_opt.model import _flat_target as flat_target
from reflector_opt.model import _operating as operating
from reflector_opt.model._flat_target import MeasuredCurve
from reflector_opt.model._sensor_file import check_sensor, sensor_from_dict, sensor_to_dict
from reflector_opt.util._errors import InputError


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
    package_mm : tuple of float, optional
        The part's package (across the emitter–detector line, along it, along the optical
        axis), mm: the window and channel the printed body cuts for it
        (:func:`reflector_opt.design._parts.package_parameters`). None (the presets) leaves the
        package to the CAD parameters (``sensor_width_mm``, ``sensor_length_mm``,
        ``sensor_depth_mm``); a part of the sensor catalogue
        (:mod:`reflector_opt.model._catalogue`) carries its own.
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
    package_mm: tuple[float, float, float] | None = None

    def __post_init__(self):
        check_sensor(self)

    @property
    def led_current_a(self):
        """LED forward current I_F = (Vcc − V_F) / R1, A (:func:`.electronics.led_current`)."""
        return electronics.led_current(self.supply_v, self.led_forward_v, self.led_resistor_ohm)

    def collector_current(self, coupling):
        """Collector current I_C, A, at coupling η (:func:`.electronics.collector_current`)."""
        return electronics.collector_current(
            coupling,
            current_gain=self.current_gain,
            led_current_a=self.led_current_a,
            dark_current_a=self.dark_current_a,
        )

    def output_voltage(self, coupling):
        """Output voltage, V, at coupling η, as calibrated (the voltage pipeline,
        :func:`.operating.readings`, for this sensor alone)."""
        eta = np.asarray(coupling, dtype=float)[..., None]
        return operating.readings(eta, (self,))[..., 0][()]

    def coupling_from_voltage(self, volts):
        """Coupling η giving ``volts`` (:func:`.electronics.coupling_from_voltage`)."""
        return electronics.coupling_from_voltage(
            volts,
            current_gain=self.current_gain,
            led_current_a=self.led_current_a,
            supply_v=self.supply_v,
            load_resistor_ohm=self.load_resistor_ohm,
            dark_current_a=self.dark_current_a,
        )

    def flat_coupling(self, distance_mm, reflectance=1.0, specular_fraction=1.0):
        """Modelled coupling η against a flat target (:func:`.flat_target.flat_coupling`)."""
        return flat_target.flat_coupling(self, distance_mm, reflectance, specular_fraction)

    def flat_correction(self, distance_mm):
        """Measured over modelled flat coupling (:func:`.flat_target.flat_correction`)."""
        return flat_target.flat_correction(self, distance_mm)

    def with_(self, **changes):
        """Return a copy with some parameters replaced (validated again)."""
        return replace(self, **changes)

    def to_dict(self):
        """Parameters as a JSON-ready dict (:func:`.sensor_file.sensor_to_dict`)."""
        return sensor_to_dict(self)

    @classmethod
    def from_dict(cls, data, where="sensor model"):
        """Build from :meth:`to_dict` output; a bad, unknown or missing key is an InputError."""
        return sensor_from_dict(cls, data, where)


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
