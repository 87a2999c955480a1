"""The sensor's light path against temperature: LED output, drive current, detector gain, dark
current and the LED's self-heating.

A unit calibrated at one temperature and used at another sees its collector current change
although the pose has not (docs/conditions.md, "Temperature"). With ΔT the change of the
junction temperatures from calibration to use, the circuit of :mod:`.electronics` gives

    I_F(T)    = (Vcc − V_F − β_F · ΔT) / R1                     (V_F falls by −β_F per K)
    P_E(T)    ∝ I_F(T) · (1 + α_E · ΔT)                           (LED radiant efficiency)
    I_C(T)    = G · (1 + α_G · ΔT) · I_F(T) · η + I_dark(T)       (detector gain)
    I_dark(T) = I_dark,0 · 2^(ΔT / T_2)                           (dark current doubles every T_2)

so the photocurrent is multiplied by :func:`photocurrent_factor`, (1 + α_E ΔT)(1 + α_G ΔT)
(1 − β_F ΔT / (Vcc − V_F)), and the dark current grows by :func:`dark_current_a`.

Where the datasheet publishes the sensor's relative collector current against ambient
temperature at a constant I_F — the LED and the detector together, as the VCNT2020's Fig. 8
(at I_F = 10, 20 and 50 mA, the three curves one within 2 %) — that curve is used as
published: its slope α_C and curvature κ_C about 25 °C replace the split,

    P_E · G (T) ∝ 1 + α_C ΔT + κ_C ΔT²                           (constant I_F)

and the circuit's drive current, set by R1 and V_F(T), is multiplied on as before. The
published curve is carried to the circuit's own I_F (a few mA, below the datasheet's 10 mA)
at the same coefficients: the curves do not move with I_F over 10-50 mA. A part with no
such curve keeps the split, with the curvature κ_C (0 unless stated). The
coefficients are a part's datasheet curves linearised about 25 °C (relative output against
ambient temperature; forward voltage against temperature; dark current against
temperature), held per catalogue part with their kind and source
(:mod:`reflector_opt.model._catalogue`).

Self-heating: the LED dissipates V_F · I_F and its junction rises by
ΔT_self = R_th · V_F · I_F · duty above the ambient (:func:`self_heating_k`), duty the share
of time it is on (1 with all LEDs on; 1/N driven in turn). A unit calibrated warm and used
warm does not see it; one read from a cold start does, until the junction settles.
"""

from dataclasses import dataclass, fields

import numpy as np

from reflector_opt.util._errors import InputError


@dataclass(frozen=True)
class ThermalCoefficients:
    """The temperature coefficients of one sensor part, linearised about 25 °C.

    Parameters
    ----------
    led_output_per_k : float
        Relative change of the LED's radiant output per kelvin at a fixed forward current,
        1/K (GaAs and GaAlAs IR LEDs: about −0.003 to −0.008 /K).
    detector_gain_per_k : float
        Relative change of the phototransistor's collector current per kelvin at a fixed
        irradiance, 1/K (the current gain rises with temperature).
    forward_voltage_v_per_k : float
        Change of the LED forward voltage per kelvin, V/K (about −1.5 to −2 mV/K); through
        R1 it changes the drive current.
    dark_current_a : float
        Collector dark current I_CEO at 25 °C, A.
    dark_doubling_k : float
        Temperature rise that doubles the dark current, K (silicon: about 8–10 K).
    thermal_resistance_k_per_w : float
        LED junction-to-ambient thermal resistance, K/W (self-heating).
    output_per_k : float or None
        Relative change per kelvin of the collector current at a constant forward current,
        LED and detector together (the datasheet's curve of relative output against
        ambient temperature), 1/K; when given it replaces ``led_output_per_k`` and
        ``detector_gain_per_k``.
    output_per_k2 : float
        Curvature of that relative output about 25 °C, 1/K² (dome-shaped curves: about
        −3e-5 to −5e-5).
    """

    led_output_per_k: float = -0.005
    detector_gain_per_k: float = 0.002
    forward_voltage_v_per_k: float = -0.0018
    dark_current_a: float = 1e-8
    dark_doubling_k: float = 10.0
    thermal_resistance_k_per_w: float = 500.0
    output_per_k: float | None = None
    output_per_k2: float = 0.0

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if value is not None and not np.isfinite(value):
                raise InputError(f"{f.name}: must be finite, got {value}")
        for name in ("led_output_per_k", "detector_gain_per_k", "output_per_k"):
            if getattr(self, name) is not None and abs(getattr(self, name)) > 0.05:
                raise InputError(
                    f"{name}: expected a relative change per kelvin within ±0.05 "
                    f"(±5 %/K), got {getattr(self, name)}"
                )
        if abs(self.forward_voltage_v_per_k) > 0.02:
            raise InputError(
                "forward_voltage_v_per_k: expected volts per kelvin within ±0.02, got "
                f"{self.forward_voltage_v_per_k}"
            )
        if abs(self.output_per_k2) > 1e-3:
            raise InputError(
                "output_per_k2: expected a curvature within ±1e-3 per kelvin squared, got "
                f"{self.output_per_k2}"
            )
        if not 0.0 <= self.dark_current_a <= 1e-4:
            raise InputError(f"dark_current_a: expected 0–1e-4 A, got {self.dark_current_a}")
        if not self.dark_doubling_k > 0.0:
            raise InputError(f"dark_doubling_k: must be positive, got {self.dark_doubling_k}")
        if not 0.0 <= self.thermal_resistance_k_per_w <= 1e4:
            raise InputError(
                "thermal_resistance_k_per_w: expected 0–10000 K/W, got "
                f"{self.thermal_resistance_k_per_w}"
            )


def photocurrent_factor(delta_t_k, coefficients, model):
    """Photocurrent at ΔT over photocurrent at the calibration temperature (dimensionless).

    ``(1 + α_E ΔT) · (1 + α_G ΔT) · (1 + κ_C ΔT²) · (1 − β_F ΔT / (Vcc − V_F))``, the product
    of the LED's radiant efficiency, the detector's gain and the drive current
    I_F = (Vcc − V_F)/R1, or ``(1 + α_C ΔT + κ_C ΔT²) · (1 − β_F ΔT / (Vcc − V_F))`` where the
    part's published curve at constant I_F gives α_C (module notes).

    Parameters
    ----------
    delta_t_k : float or array_like
        Junction temperature change from calibration to use, K.
    coefficients : ThermalCoefficients
    model : reflector_opt.model._sensors.SensorModel
        Supplies Vcc and V_F.

    Returns
    -------
    float or numpy.ndarray
        The factor, shape of ``delta_t_k``.
    """
    dt = np.asarray(delta_t_k, dtype=float)
    headroom = model.supply_v - model.led_forward_v
    drive = 1.0 - coefficients.forward_voltage_v_per_k * dt / headroom
    curvature = coefficients.output_per_k2 * dt**2
    if coefficients.output_per_k is not None:
        return (1.0 + coefficients.output_per_k * dt + curvature) * drive
    led = 1.0 + coefficients.led_output_per_k * dt
    detector = 1.0 + coefficients.detector_gain_per_k * dt
    return led * detector * (1.0 + curvature) * drive


def dark_current_a(delta_t_k, coefficients):
    """Dark current I_dark,0 · 2^(ΔT / T_2) at ΔT from 25 °C, A.

    Parameters
    ----------
    delta_t_k : float or array_like
        Temperature above 25 °C, K.
    coefficients : ThermalCoefficients

    Returns
    -------
    float or numpy.ndarray
    """
    dt = np.asarray(delta_t_k, dtype=float)
    return coefficients.dark_current_a * np.exp2(dt / coefficients.dark_doubling_k)


def self_heating_k(model, coefficients, duty=1.0):
    """The LED junction's steady rise over the ambient from its own dissipation, K.

    ΔT_self = R_th · V_F · I_F · duty (module notes).

    Parameters
    ----------
    model : reflector_opt.model._sensors.SensorModel
    coefficients : ThermalCoefficients
    duty : float
        Share of the time the LED is on, 0–1.

    Returns
    -------
    float
    """
    if not 0.0 <= duty <= 1.0:
        raise InputError(f"duty: expected a share of time from 0 to 1, got {duty}")
    power_w = model.led_forward_v * model.led_current_a
    return coefficients.thermal_resistance_k_per_w * power_w * duty
