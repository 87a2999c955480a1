"""An independent truth for the in-use error of a perfectly calibrated unit.

A calibrated unit maps its ADC readings back to pitch and roll with the readings it gave at
calibration. In use, something differs from calibration (the sensors' temperature, the sphere's
centre shifted within the joint's clearance, the supply, ambient light), so the same pose gives
other readings and the unit reads another pose. This module computes that error from physics
written here, sharing no code with the package's error budget
(``reflector_opt.analysis._budget``) nor with the package's circuit and temperature models: it
imports nothing of ``reflector_opt.analysis``, ``reflector_opt.model._forward``,
``.temperature``, ``.operating``, ``.electronics``, ``.kernel`` or ``.interpolation``. It takes
from the package only

* the optical coupling η, from the slow exact reference
  :func:`reflector_opt.model._reference.direct_response` (per-pose rotation, Eq 3 distance,
  surface couplings at every pose), and
* the design's fields: the reflector's sphere (``reflector.centre_mm``, ``radius_mm``), the
  sensors, and each sensor model's circuit values (``supply_v``, ``led_forward_v``,
  ``led_resistor_ohm``, ``load_resistor_ohm``, ``current_gain``, ``saturation_v``,
  ``dark_current_a``, ``name``); the parts' switching times are transcribed here with the
  temperature figures (:data:`PARTS`), not taken from the package's catalogue.

The circuit (the paper's Fig. 2f), per sensor, at a junction temperature T (°C):

    I_F   = (Vcc − V_F(T, I_F)) / R1                      (solved for I_F, scalar root)
    I_C   = G · η · I_F · k(T) + I_dark(T) + I_amb
    V_out = clip(Vcc − R2 · I_C, V_CE(sat), Vcc)
    reading = V_out                      (ADC with a fixed reference)
            = V_out · Vcc_nom / Vcc      (ratiometric ADC: the reference is the supply)

with, from the part's datasheet figures transcribed below (:data:`PARTS`),

    V_F(T, I_F) = V_F,nom + [V_pub(T) − V_pub(25 °C)] + s · ln(I_F / I_F,nom)
    k(T)        = C(T) / C(T_cal)         (C: the published relative collector current at
                                           constant I_F against ambient temperature)
    I_dark(T)   = I_dark,model + I_CEO(25 °C) · 2^((T − 25 °C) / T_2)

where V_F,nom = ``led_forward_v`` is taken as the forward voltage at 25 °C at the design's
nominal current I_F,nom = (``supply_v`` − ``led_forward_v``) / R1, V_pub is the published
V_F-against-temperature curve at the datasheet's nominal test current (a natural cubic spline
through the read-off points; a part without the curve uses a linear coefficient), s the
forward voltage's change per e-fold of current (from the published curves at several currents
at 25 °C, or an assumed n·V_T), C a natural cubic spline through the read-off points, I_CEO and
its doubling interval T_2 published or derived from the dark-current curve. A part without a
published C(T) needs a stated linear coefficient, ``InUse.linear_output_per_k`` (then
k(T) = 1 + c · (T − T_cal)).

The joint's clearance moves the sphere's centre by δ in the lower body's (base) frame after
the rotation: s1 = R · s0 + δ, R = Rx(α) · Ry(γ). The package describes the sphere by its centre
s0 in the rotating frame, so a shifted pose is given to ``direct_response`` as a design whose
centre is s0' = s0 + Rᵀ · δ (then R · s0' = R · s0 + δ), one design per pose.

With a :class:`Drive`, the readings are those of the unit's read-out in time: the LEDs lit
window by window as the scheme lights them (all at once, one at a time, or one at a time on
and off with the difference kept), a neighbouring unit's light on each detector in the window
before the unit's own, the ambient light's constant part and flicker, and each detector a
first-order system of the part's published rise and fall times carried to its load, sampled
at the end of its window (the equations in :class:`Drive`). The calibration is made with the
same read-out, so what it keeps of each LED's light is learned; what differs in use is not.

The inversion (:func:`read_angles`) is a perfectly calibrated unit: per pose, the angles whose
nominal readings (calibration state, :class:`InUse` ``()``) match the readings in least squares
(:func:`scipy.optimize.least_squares`, Levenberg–Marquardt, tolerances 1e-14).
"""

from __future__ import annotations

import dataclasses
import logging
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq, least_squares

from reflector_opt.model._reference import direct_response

__all__ = [
    "PARTS",
    "Drive",
    "InUse",
    "PartFigures",
    "Table",
    "centre_in_rotating_frame",
    "coupling",
    "dark_current_a",
    "eq3_distance_mm",
    "forward_voltage_v",
    "in_use_error_deg",
    "led_current_a",
    "part_figures",
    "read_angles",
    "readings",
    "relative_output",
    "rotation_matrix",
    "shifted_design",
]

#: Thermal voltage kT/q at 25 °C, V (k = 1.380649e-23 J/K, q = 1.602176634e-19 C).
THERMAL_VOLTAGE_25C_V = 1.380649e-23 * 298.15 / 1.602176634e-19


# ---------------------------------------------------------------------------------------------
# Datasheet figures, transcribed from /work/research/figures.md (read-offs of the datasheets'
# curves, PDF pages rendered at 250 dpi; ±1 small grid division)
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Table:
    """Points read off a published curve.

    Parameters
    ----------
    temperature_c : tuple of float
        Ambient temperatures, °C, increasing.
    values : tuple of float
        The curve's values at those temperatures (unit as the curve's: relative, or V).
    source : str
        Document and figure the points were read from.
    kind : str
        ``"read-off"`` (read by eye from the curve) or ``"published"``.
    """

    temperature_c: tuple
    values: tuple
    source: str
    kind: str = "read-off"

    def spline(self):
        """Natural cubic spline through the points (C², passes through every point)."""
        return CubicSpline(
            np.asarray(self.temperature_c, float), np.asarray(self.values, float), bc_type="natural"
        )

    def check_range(self, t_c):
        """Raise ValueError if any temperature lies outside the published range (°C)."""
        t = np.asarray(t_c, float)
        lo, hi = self.temperature_c[0], self.temperature_c[-1]
        if np.any(t < lo) or np.any(t > hi):
            raise ValueError(
                f"temperature {t} °C outside the published range {lo}…{hi} °C of {self.source}"
            )


@dataclass(frozen=True)
class PartFigures:
    """The temperature figures of one reflective sensor part.

    Parameters
    ----------
    name : str
        Part name as the design's sensor models spell it.
    relative_output : Table or None
        Relative collector current against ambient temperature at constant I_F (LED output
        and phototransistor gain together), or None when the datasheet publishes none.
    forward_voltage : Table or None
        LED forward voltage against ambient temperature at the datasheet's nominal test
        current, V; None when not published (then ``forward_voltage_per_k`` is used).
    forward_voltage_per_k : float
        dV_F/dT, V/K, used only without ``forward_voltage``.
    forward_voltage_per_ln_current : float
        s = dV_F / d ln I_F at 25 °C, V (per e-fold of LED current).
    dark_current_25c_a : float
        Collector dark current I_CEO at 25 °C, A.
    dark_doubling_k : float
        Temperature rise that doubles I_CEO, K.
    sources : dict of str to str
        Where each figure comes from and of what kind (published, read-off, derived, assumed).
    switching_s : tuple of float
        The phototransistor's 10–90 % rise and 90–10 % fall times and the load they are stated
        at: (t_r in s, t_f in s, R_test in Ω).
    """

    name: str
    relative_output: Table | None
    forward_voltage: Table | None
    forward_voltage_per_k: float
    forward_voltage_per_ln_current: float
    dark_current_25c_a: float
    dark_doubling_k: float
    sources: dict
    switching_s: tuple = (40e-6, 40e-6, 100.0)


def _vcnt2020_ln_current_slope():
    """s of the VCNT2020, V: least-squares slope of V_F against ln I_F at 25 °C over the
    published 10, 20 and 50 mA curves (doc 84285 Fig. 5: 1.205, 1.243, 1.316 V)."""
    ln_i = np.log([10e-3, 20e-3, 50e-3])
    v = np.array([1.205, 1.243, 1.316])
    return float(np.polyfit(ln_i, v, 1)[0])


#: The VCNT2020's forward voltage at 25 °C is read at 10/20/50 mA (doc 84285 Fig. 5); the
#: other two curves' points, kept for the record and for s.
VCNT2020_VF_OTHER_CURRENTS = {
    10e-3: Table(
        (-40.0, 0.0, 25.0, 50.0, 100.0),
        (1.277, 1.232, 1.205, 1.179, 1.127),
        "Vishay VCNT2020, doc 84285 Rev. 1.3, Fig. 5 (V_F vs T_amb), I_F = 10 mA, tp = 20 ms",
    ),
    50e-3: Table(
        (-40.0, 0.0, 25.0, 50.0, 100.0),
        (1.385, 1.340, 1.316, 1.297, 1.258),
        "Vishay VCNT2020, doc 84285 Rev. 1.3, Fig. 5 (V_F vs T_amb), I_F = 50 mA, tp = 20 ms",
    ),
}

#: VCNT2020 dark current read off doc 84285 Fig. 6 (I_CEO vs T_amb, V_CE = 20 V), A.
VCNT2020_DARK_CURVE = Table(
    (25.0, 50.0, 75.0, 100.0),
    (1e-9, 18e-9, 0.22e-6, 3e-6),
    "Vishay VCNT2020, doc 84285 Rev. 1.3, Fig. 6 (I_CEO vs T_amb, V_CE = 20 V)",
)

_GENERIC_S = 2.0 * THERMAL_VOLTAGE_25C_V  # n = 2: assumed for a GaAs IRED at a few mA

PARTS = {
    "VCNT2020": PartFigures(
        name="VCNT2020",
        relative_output=Table(
            (-40.0, -25.0, 0.0, 25.0, 50.0, 75.0, 100.0),
            (0.73, 0.80, 0.91, 1.00, 1.10, 1.20, 1.30),
            "Vishay VCNT2020, doc 84285 Rev. 1.3 (21-Jan-2019), Fig. 8 (relative collector "
            "current vs T_amb), I_F = 20 mA, V_CE = 5 V, d = 1 mm; 100 °C read 1.29–1.31",
        ),
        forward_voltage=Table(
            (-40.0, 0.0, 25.0, 50.0, 100.0),
            (1.312, 1.267, 1.243, 1.219, 1.173),
            "Vishay VCNT2020, doc 84285 Rev. 1.3, Fig. 5 (V_F vs T_amb), I_F = 20 mA, tp = 20 ms",
        ),
        forward_voltage_per_k=-1.0e-3,
        forward_voltage_per_ln_current=_vcnt2020_ln_current_slope(),
        dark_current_25c_a=1e-9,
        dark_doubling_k=75.0 * np.log(2.0) / np.log(3e-6 / 1e-9),
        sources={
            "relative_output": "read-off: doc 84285 Fig. 8",
            "forward_voltage": "read-off: doc 84285 Fig. 5 (20 mA curve)",
            "forward_voltage_per_k": "published: TK_VF −1.0 mV/K typ at 20 mA (basic "
            "characteristics table); unused, the curve is used",
            "forward_voltage_per_ln_current": "derived: LSQ slope of V_F vs ln I_F at 25 °C, "
            "Fig. 5 (10/20/50 mA: 1.205/1.243/1.316 V)",
            "dark_current_25c_a": "published: I_CEO 1 nA typ, V_CE = 5 V, 25 °C",
            "dark_doubling_k": "derived: Fig. 6, ×3000 from 25 to 100 °C (1 nA → 3 µA): "
            "75 K · ln 2 / ln 3000 ≈ 6.5 K",
            "switching_s": "published: t_r 10 µs, t_f 15 µs typ at I_C 0.8 mA, V_CE 5 V, "
            "R_L 100 Ω (basic characteristics table)",
        },
        switching_s=(10e-6, 15e-6, 100.0),
    ),
    "TCRT5000": PartFigures(
        name="TCRT5000",
        relative_output=Table(
            (-25.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 75.0, 90.0, 100.0),
            (0.855, 0.91, 0.94, 0.965, 0.985, 1.003, 1.008, 1.00, 0.98, 0.945, 0.895, 0.855),
            "Vishay TCRT5000, doc 83760 Rev. 1.7 (17-Aug-09), Fig. 5 (relative current "
            "transfer ratio vs T_amb), I_F = 20 mA, V_CE = 5 V",
        ),
        forward_voltage=None,
        forward_voltage_per_k=-1.5e-3,
        forward_voltage_per_ln_current=_GENERIC_S,
        dark_current_25c_a=10e-9,
        dark_doubling_k=6.5,
        sources={
            "relative_output": "read-off: doc 83760 Fig. 5 (dome, maximum near 40 °C)",
            "forward_voltage_per_k": "assumed: −1.5 mV/K (range −2.0…−1.0 mV/K; not stated "
            "in Rev 1.7; VCNT2020 −1.0 published, ITR8307 −1.2, QRE1113 −1.8…−2.0 read-off)",
            "forward_voltage_per_ln_current": "assumed: n·V_T with n = 2 (≈ 51 mV)",
            "dark_current_25c_a": "published: I_CEO 10 nA typ at V_CE = 20 V, 25 °C",
            "dark_doubling_k": "assumed: 6.5 K (no I_CEO(T) curve; VCNT2020 Fig. 6 ≈ 6.5 K, "
            "ITR8307 ≈ 6.4 K)",
        },
    ),
    "CNY70": PartFigures(
        name="CNY70",
        relative_output=Table(
            (-25.0, -10.0, 0.0, 20.0, 25.0, 30.0, 45.0, 60.0, 70.0, 75.0),
            (0.89, 0.93, 0.955, 0.995, 1.00, 1.005, 1.02, 1.005, 0.975, 0.96),
            "Vishay CNY70, doc 83751 Rev. 1.8 (30-Jul-12), Fig. 4 (relative current transfer "
            "ratio vs T_amb), I_F = 20 mA, V_CE = 5 V, d = 0.3 mm",
        ),
        forward_voltage=None,
        forward_voltage_per_k=-1.5e-3,
        forward_voltage_per_ln_current=_GENERIC_S,
        dark_current_25c_a=10e-9,
        dark_doubling_k=6.5,
        sources={
            "relative_output": "read-off: doc 83751 Fig. 4 (dome, maximum near 45 °C)",
            "forward_voltage_per_k": "assumed: −1.5 mV/K (not stated in Rev 1.8)",
            "forward_voltage_per_ln_current": "assumed: n·V_T with n = 2 (≈ 51 mV)",
            "dark_current_25c_a": "assumed: 10 nA typ (only 200 nA max published, V_CE = 20 V)",
            "dark_doubling_k": "assumed: 6.5 K (no I_CEO(T) curve)",
        },
    ),
    "NJL5901R-2": PartFigures(
        name="NJL5901R-2",
        relative_output=None,
        forward_voltage=None,
        forward_voltage_per_k=-1.5e-3,
        forward_voltage_per_ln_current=_GENERIC_S,
        dark_current_25c_a=10e-9,
        dark_doubling_k=8.0,
        sources={
            "all": "assumed: no NJL5901R-2 figure found (figures.md A1); TK_VF −1.5 mV/K "
            "(range −2.0…−1.0), I_CEO 10 nA (≤ 100–200 nA max class), doubling 8 K (6–10 K), "
            "n = 2; no relative-output curve: pass InUse.linear_output_per_k; t_r = t_f = "
            "40 µs at 100 Ω (10–40 µs at 100 Ω–1 kΩ, the slow end, at the lower test load); "
            "the TCRT5000 and CNY70 state no switching times and take the same",
        },
    ),
}


def part_figures(name):
    """The :class:`PartFigures` of a part by name; unknown parts get the NJL5901R-2's assumed
    generic figures (no published curve) under their own name.

    Parameters
    ----------
    name : str

    Returns
    -------
    PartFigures
    """
    if name in PARTS:
        return PARTS[name]
    return dataclasses.replace(PARTS["NJL5901R-2"], name=name)


# ---------------------------------------------------------------------------------------------
# Circuit
# ---------------------------------------------------------------------------------------------


def relative_output(part, t_c, calibration_c=25.0, linear_per_k=None):
    """k(T): relative collector current at constant I_F, 1 at the calibration temperature.

    k(T) = C(T) / C(T_cal), C the natural cubic spline through the part's published read-off
    points (:attr:`PartFigures.relative_output`), or k(T) = 1 + c · (T − T_cal) when
    ``linear_per_k`` = c (1/K) is given (which overrides the curve).

    Parameters
    ----------
    part : PartFigures
    t_c : float or array_like
        Temperature, °C.
    calibration_c : float
        Calibration temperature T_cal, °C.
    linear_per_k : float or None
        Linear relative coefficient c, 1/K.

    Returns
    -------
    numpy.ndarray
        k, dimensionless. Raises ValueError for a part without a curve and no ``linear_per_k``
        (unless T = T_cal), or outside the curve's published range.
    """
    t = np.asarray(t_c, float)
    if linear_per_k is not None:
        return 1.0 + float(linear_per_k) * (t - calibration_c)
    if part.relative_output is None:
        if np.all(t == calibration_c):
            return np.ones_like(t)
        raise ValueError(
            f"{part.name}: no published relative-output curve; give InUse.linear_output_per_k"
        )
    table = part.relative_output
    table.check_range(np.append(t, calibration_c))
    spline = table.spline()
    return spline(t) / spline(calibration_c)


def forward_voltage_v(part, model, t_c, led_current):
    """V_F(T, I_F), V.

    V_F = V_F,nom + [V_pub(T) − V_pub(25 °C)] + s · ln(I_F / I_F,nom), with V_F,nom the
    model's ``led_forward_v`` (taken at 25 °C and at I_F,nom = (``supply_v`` −
    ``led_forward_v``) / R1), V_pub the natural cubic spline through the part's published
    V_F(T) points at its nominal test current (or ``forward_voltage_per_k`` · (T − 25 °C) for a
    part without the curve), s = ``forward_voltage_per_ln_current``.

    Parameters
    ----------
    part : PartFigures
    model : SensorModel
        Only its circuit values are read.
    t_c : float
        Junction temperature, °C.
    led_current : float
        I_F, A.

    Returns
    -------
    float
    """
    if part.forward_voltage is None:
        thermal = part.forward_voltage_per_k * (t_c - 25.0)
    else:
        part.forward_voltage.check_range(t_c)
        spline = part.forward_voltage.spline()
        thermal = float(spline(t_c) - spline(25.0))
    nominal = (model.supply_v - model.led_forward_v) / model.led_resistor_ohm
    return (
        model.led_forward_v
        + thermal
        + part.forward_voltage_per_ln_current * np.log(led_current / nominal)
    )


def led_current_a(part, model, t_c, supply_v):
    """LED current I_F, A: the root of R1 · I_F − (Vcc − V_F(T, I_F)) = 0.

    The left side rises strictly with I_F (R1 + s / I_F > 0), is negative as I_F → 0 (V_F →
    −∞ through the log term) and positive at I_F = Vcc / R1, so the root is unique; found by
    Brent's method to 1e-18 A.

    Parameters
    ----------
    part : PartFigures
    model : SensorModel
    t_c : float
        Junction temperature, °C.
    supply_v : float
        Vcc, V.

    Returns
    -------
    float
    """
    r1 = model.led_resistor_ohm

    def excess(i):
        return r1 * i - (supply_v - forward_voltage_v(part, model, t_c, i))

    return brentq(excess, 1e-12, supply_v / r1, xtol=1e-18, rtol=1e-15, maxiter=200)


def dark_current_a(part, model, t_c):
    """I_dark(T) = ``model.dark_current_a`` + I_CEO(25 °C) · 2^((T − 25 °C) / T_2), A.

    Parameters
    ----------
    part : PartFigures
    model : SensorModel
    t_c : float
        Junction temperature, °C.

    Returns
    -------
    float
    """
    return model.dark_current_a + part.dark_current_25c_a * 2.0 ** (
        (t_c - 25.0) / part.dark_doubling_k
    )


# ---------------------------------------------------------------------------------------------
# Geometry (own Eq 1–3) and the coupling with a shifted sphere
# ---------------------------------------------------------------------------------------------


def rotation_matrix(pitch_deg, roll_deg):
    """R = Rx(α) · Ry(γ) (paper Eq 1; active, right-handed), shape P + (3, 3).

    Parameters
    ----------
    pitch_deg, roll_deg : array_like
        Pitch γ (about y) and roll α (about x), degrees.

    Returns
    -------
    numpy.ndarray
    """
    g = np.radians(np.asarray(pitch_deg, float))
    a = np.radians(np.asarray(roll_deg, float))
    g, a = np.broadcast_arrays(g, a)
    cg, sg, ca, sa = np.cos(g), np.sin(g), np.cos(a), np.sin(a)
    one, zero = np.ones_like(g), np.zeros_like(g)

    def matrix(rows):
        return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)

    ry = matrix([(cg, zero, sg), (zero, one, zero), (-sg, zero, cg)])
    rx = matrix([(one, zero, zero), (zero, ca, -sa), (zero, sa, ca)])
    return rx @ ry


def centre_in_rotating_frame(design, pitch_deg, roll_deg, shift_mm):
    """s0' = s0 + Rᵀ · δ: the zero-pose centre that puts the sphere at R · s0 + δ, mm.

    Parameters
    ----------
    design : Design
    pitch_deg, roll_deg : array_like
        Shape P, degrees.
    shift_mm : array_like
        δ, shape (3,), in the base frame, mm.

    Returns
    -------
    numpy.ndarray
        Shape P + (3,), mm.
    """
    r = rotation_matrix(pitch_deg, roll_deg)
    delta = np.asarray(shift_mm, float)
    return np.asarray(design.reflector.centre_mm, float) + np.einsum("...ji,j->...i", r, delta)


def eq3_distance_mm(design, pitch_deg, roll_deg, shift_mm=(0.0, 0.0, 0.0)):
    """Own Eq 1–3: d = |f − (R · s0 + δ)| − r_s per sensor, mm, shape P + (n_sensors,).

    Parameters
    ----------
    design : Design
    pitch_deg, roll_deg : array_like
        Degrees.
    shift_mm : array_like
        δ in the base frame, mm.

    Returns
    -------
    numpy.ndarray
    """
    r = rotation_matrix(pitch_deg, roll_deg)
    s1 = r @ np.asarray(design.reflector.centre_mm, float) + np.asarray(shift_mm, float)
    f = np.array([s.position_mm for s in design.sensors], float)
    return np.linalg.norm(f - s1[..., None, :], axis=-1) - design.reflector.radius_mm


@contextmanager
def _quiet_design_checks():
    """Silence the design checks' warnings (the bearing's rated tilt, said once already when the
    design was loaded) while the per-pose copies are built; errors still raise."""
    loggers = [logging.getLogger("reflector_opt.design"), logging.getLogger("reflector_opt")]
    levels = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.ERROR)
    try:
        yield
    finally:
        for lg, level in zip(loggers, levels, strict=True):
            lg.setLevel(level)


def shifted_design(design, pitch_deg, roll_deg, shift_mm):
    """The design whose sphere, at this one pose, sits at R · s0 + δ (centre s0 + Rᵀ · δ).

    Parameters
    ----------
    design : Design
    pitch_deg, roll_deg : float
        One pose, degrees.
    shift_mm : array_like
        δ, shape (3,), base frame, mm.

    Returns
    -------
    Design
        Validated again by the Design's own construction (its warnings silenced).
    """
    centre = centre_in_rotating_frame(design, float(pitch_deg), float(roll_deg), shift_mm)
    reflector = dataclasses.replace(design.reflector, centre_mm=tuple(float(c) for c in centre))
    with _quiet_design_checks():
        return design.replace(reflector=reflector)


def coupling(design, pitch_deg, roll_deg, shift_mm=(0.0, 0.0, 0.0), distance=False):
    """Optical coupling η per pose and sensor from ``direct_response``, shape (P, n_sensors).

    Parameters
    ----------
    design : Design
    pitch_deg, roll_deg : array_like
        Flat arrays of length P, degrees.
    shift_mm : array_like
        Sphere centre shift δ in the base frame, mm (one design per pose when non-zero).
    distance : bool
        Also return direct_response's Eq 3 distances, mm.

    Returns
    -------
    numpy.ndarray or (numpy.ndarray, numpy.ndarray)
    """
    pitch = np.atleast_1d(np.asarray(pitch_deg, float))
    roll = np.atleast_1d(np.asarray(roll_deg, float))
    if not np.any(np.asarray(shift_mm, float)):
        d, eta, _ = direct_response(design, pitch, roll)
    else:
        rows = [
            direct_response(shifted_design(design, p, r, shift_mm), p, r)
            for p, r in zip(pitch, roll, strict=True)
        ]
        d = np.array([row[0] for row in rows])
        eta = np.array([row[1] for row in rows])
    return (eta, d) if distance else eta


# ---------------------------------------------------------------------------------------------
# The in-use state, readings, inversion
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class InUse:
    """What differs in use from calibration; every default is "nothing changed".

    Parameters
    ----------
    delta_t_k : float or tuple of float
        Junction temperature change per sensor (one value for all, or one per sensor), K.
    centre_shift_mm : tuple of float
        Sphere centre shift δ in the base frame, after the rotation, mm.
    supply_change_v : float
        Change of Vcc (LED and collector circuits together), V.
    adc_reference : str
        ``"fixed"`` (reading = V_out) or ``"ratiometric"`` (reading = V_out · Vcc_nom / Vcc).
    ambient_a : float or tuple of float
        Extra collector current from ambient light per sensor, A.
    linear_output_per_k : float or None
        Linear k(T) = 1 + c · ΔT with c in 1/K, overriding the parts' curves (needed for a
        part without a published curve when ΔT ≠ 0).
    flicker_a : float
        Peak of the ambient light's flicker as a collector current, common to the sensors, A
        (read with a :class:`Drive`: the readings are those of the frame at which it lowers
        the outputs most).
    flicker_hz : float
        Its frequency, Hz.
    neighbour_pose_deg : tuple of float
        The neighbouring unit's (pitch, roll), degrees; straight at calibration.
    """

    delta_t_k: float | tuple = 0.0
    centre_shift_mm: tuple = (0.0, 0.0, 0.0)
    supply_change_v: float = 0.0
    adc_reference: str = "fixed"
    ambient_a: float | tuple = 0.0
    linear_output_per_k: float | None = None
    flicker_a: float = 0.0
    flicker_hz: float = 100.0
    neighbour_pose_deg: tuple = (0.0, 0.0)

    def __post_init__(self):
        if self.adc_reference not in ("fixed", "ratiometric"):
            raise ValueError(f"adc_reference: 'fixed' or 'ratiometric', got {self.adc_reference!r}")
        if np.shape(self.centre_shift_mm) != (3,):
            raise ValueError("centre_shift_mm: three components, mm")


def _per_sensor(value, n, name):
    values = np.asarray(value, float)
    if values.ndim == 0:
        return np.full(n, float(values))
    if values.shape != (n,):
        raise ValueError(f"{name}: one value or {n} (one per sensor), got {values.shape}")
    return values.astype(float)


def _circuit(design, state, calibration_c):
    """Per-sensor constants of the map η → reading: reading = scale · clip(vcc − r2 · (gain · η
    + extra), vsat, vcc). Returns a dict of arrays of length n_sensors."""
    models = design.models
    n = len(models)
    dt = _per_sensor(state.delta_t_k, n, "delta_t_k")
    ambient = _per_sensor(state.ambient_a, n, "ambient_a")
    out = {k: np.empty(n) for k in ("gain", "extra", "vcc", "r2", "vsat", "scale", "i_f", "k")}
    for j, model in enumerate(models):
        part = part_figures(model.name)
        t = calibration_c + dt[j]
        vcc = model.supply_v + state.supply_change_v
        i_f = led_current_a(part, model, t, vcc)
        k = (
            float(relative_output(part, t, calibration_c, state.linear_output_per_k))
            if dt[j] != 0
            else 1.0
        )
        out["i_f"][j] = i_f
        out["k"][j] = k
        out["gain"][j] = model.current_gain * i_f * k
        out["extra"][j] = dark_current_a(part, model, t) + ambient[j]
        out["vcc"][j] = vcc
        out["r2"][j] = model.load_resistor_ohm
        out["vsat"][j] = model.saturation_v
        out["scale"][j] = model.supply_v / vcc if state.adc_reference == "ratiometric" else 1.0
    return out


def _volts(circuit, eta):
    """Readings, V, from couplings η of shape (P, n) and :func:`_circuit` constants."""
    i_c = circuit["gain"] * eta + circuit["extra"]
    v_out = np.clip(circuit["vcc"] - circuit["r2"] * i_c, circuit["vsat"], circuit["vcc"])
    return circuit["scale"] * v_out


def _reader(design, state, calibration_c, drive):
    """The map η (P, n) → readings (P, n) of a unit in ``state`` under ``drive``."""
    circuit = _circuit(design, state, calibration_c)
    if drive is None:
        return lambda eta: _volts(circuit, eta)
    neighbour = circuit["gain"] * coupling(design, *np.transpose([state.neighbour_pose_deg]))
    return lambda eta: drive.readings(design, circuit, eta, neighbour, state)


def readings(design, pitch_deg, roll_deg, state=None, calibration_c=25.0, drive=None):
    """ADC readings of a unit in the state ``state`` at the given true poses.

    Parameters
    ----------
    design : Design
    pitch_deg, roll_deg : array_like
        Flat arrays of equal length P, degrees.
    state : InUse, optional
        Default :class:`InUse` ``()``, the calibration state.
    calibration_c : float
        Calibration temperature, °C (the state's ΔT is relative to it).
    drive : Drive, optional
        The read-out's timing (:meth:`Drive.readings`); None: every reading settled at one
        instant, no neighbour (the circuit alone).

    Returns
    -------
    numpy.ndarray
        Shape (P, n_sensors), V.
    """
    state = InUse() if state is None else state
    eta = coupling(design, pitch_deg, roll_deg, state.centre_shift_mm)
    return _reader(design, state, calibration_c, drive)(eta)


def read_angles(design, readings, start_deg, calibration_c=25.0, jac_step_deg=1e-4, drive=None):
    """The angles a perfectly calibrated unit reads: per pose, the (pitch, roll) whose nominal
    readings (:class:`InUse` ``()``, under ``drive``) match ``readings`` in least squares.

    Levenberg–Marquardt (:func:`scipy.optimize.least_squares`, ``method="lm"``, ftol = xtol =
    gtol = 1e-14) from ``start_deg``, the Jacobian by central differences of step
    ``jac_step_deg`` (it steers the iteration only; the solution is where the residual
    vanishes).

    Parameters
    ----------
    design : Design
    readings : array_like
        Shape (P, n_sensors), V.
    start_deg : array_like
        Start (pitch, roll), shape (2,) or (P, 2), degrees.
    calibration_c : float
        Calibration temperature, °C.
    jac_step_deg : float
        Central-difference step, degrees.
    drive : Drive, optional
        The read-out the unit was calibrated with (its neighbour straight).

    Returns
    -------
    numpy.ndarray
        Shape (P, 2): pitch and roll, degrees.
    """
    target = np.atleast_2d(np.asarray(readings, float))
    start = np.broadcast_to(np.asarray(start_deg, float), (len(target), 2))
    nominal = _reader(design, InUse(), calibration_c, drive)
    h = float(jac_step_deg)
    offsets = np.array([[h, 0.0], [-h, 0.0], [0.0, h], [0.0, -h]])
    out = np.empty((len(target), 2))
    for i, (v, x0) in enumerate(zip(target, start, strict=True)):

        def residual(x, v=v):
            return nominal(coupling(design, x[:1], x[1:]))[0] - v

        def jacobian(x):
            points = x + offsets
            volts = nominal(coupling(design, points[:, 0], points[:, 1]))
            return np.stack([volts[0] - volts[1], volts[2] - volts[3]], axis=-1) / (2 * h)

        fit = least_squares(
            residual, x0, jac=jacobian, method="lm", ftol=1e-14, xtol=1e-14, gtol=1e-14
        )
        out[i] = fit.x
    return out


def in_use_error_deg(design, pitch_deg, roll_deg, state, calibration_c=25.0, drive=None):
    """Signed in-use angle error of a perfectly calibrated unit, degrees.

    ``read_angles(readings(state)) − true pose``, the inversion started at the true pose, the
    unit read (and calibrated) under ``drive``.

    Parameters
    ----------
    design : Design
    pitch_deg, roll_deg : array_like
        Flat arrays of equal length P, degrees.
    state : InUse
    calibration_c : float
        Calibration temperature, °C.
    drive : Drive, optional

    Returns
    -------
    numpy.ndarray
        Shape (P, 2): (pitch, roll) errors, degrees.
    """
    truth = np.stack(
        [np.atleast_1d(np.asarray(pitch_deg, float)), np.atleast_1d(np.asarray(roll_deg, float))],
        axis=-1,
    )
    volts = readings(design, truth[:, 0], truth[:, 1], state, calibration_c, drive)
    return read_angles(design, volts, truth, calibration_c, drive=drive) - truth


# ---------------------------------------------------------------------------------------------
# The read-out's timing: which LEDs are lit when, the detector's response, the samples
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Drive:
    """How a unit's LEDs are lit and its detectors sampled, and the neighbour's light.

    A frame is M windows of one ADC conversion, t_w = 1/f_s, each; the sample of a reading is
    taken at the end of its window (the most settled instant of it):

    ``dc``
        M = n; every LED lit in every window; sensor k sampled at the end of window k.
    ``multiplexed``
        M = n; LED k lit in window k alone, sensor k sampled at its end.
    ``modulated``
        M = 2n; LED k lit in window 2k, dark in 2k + 1; sensor k sampled at the end of both,
        the reading Vcc,nom − (V_off − V_on).

    The neighbouring unit (the same design, the same read-out) runs its sequence one
    conversion ahead: its LED k is lit in the window before the one this unit's LED k is lit
    in (every window under ``dc``), and ``neighbour_share`` of its light collector current
    G · I_F · η(its pose) reaches this unit's detector k.

    Each detector's collector current answers its light u(t) (the LEDs' as above, the
    ambient's, its dark current) as a first-order system whose time constant is that of the
    direction it moves in,

        dI/dt = (u − I) / τ,   τ = τ_r where u > I, τ_f where u < I,
        τ_r,f = t_r,f / ln 9 · (R2 / R_test)^p,

    t_r, t_f the part's 10–90 % times at its test load R_test (:attr:`PartFigures.switching_s`;
    a first-order step takes τ · ln 9 from 10 to 90 %), carried to the circuit's load R2 by a
    power law of exponent p (the growth of the Miller-multiplied collector capacitance's
    charging time with the load, as the one published curve of switching time against load
    shows it: onsemi QRE1113 Fig. 7; p is a figure the caller gives). Over a window the light
    is held, the flicker included, on ``substeps`` equal steps, each exact for its held value;
    the sequence is run until every state has settled to 1e-13 of a step before the frames
    are sampled.

    Parameters
    ----------
    scheme : str
        ``"dc"``, ``"multiplexed"`` or ``"modulated"``.
    sample_rate_hz : float
        ADC conversions per second, f_s, Hz.
    neighbour_share : float
        Share of the neighbouring unit's light collector current on each detector.
    load_exponent : float
        p.
    substeps : int
        Steps per window while the light flickers.
    flicker_periods : int
        Flicker periods over which frames are sampled (the frame lowest on average kept):
        more periods at a rate the flicker does not divide meet more of its phases.
    """

    scheme: str = "dc"
    sample_rate_hz: float = 10000.0
    neighbour_share: float = 0.0
    load_exponent: float = 0.7
    substeps: int = 16
    flicker_periods: int = 1

    def __post_init__(self):
        if self.scheme not in ("dc", "multiplexed", "modulated"):
            raise ValueError(f"scheme: dc, multiplexed or modulated, got {self.scheme!r}")

    def windows(self, n):
        """(lit, sampled): lit (M, n) of bool, LED k lit in window w; sampled (n, 1 or 2):
        the windows at whose end sensor k is sampled (on, then off under ``modulated``)."""
        if self.scheme == "dc":
            return np.ones((n, n), bool), np.arange(n)[:, None]
        if self.scheme == "multiplexed":
            return np.eye(n, dtype=bool), np.arange(n)[:, None]
        lit = np.zeros((2 * n, n), bool)
        lit[2 * np.arange(n), np.arange(n)] = True
        return lit, np.stack([2 * np.arange(n), 2 * np.arange(n) + 1], axis=-1)

    def time_constants_s(self, design):
        """(τ_r, τ_f), each of shape (n,), s: the parts' switching times at the loads."""
        out = []
        for model in design.models:
            rise, fall, test_load = part_figures(model.name).switching_s
            scale = (model.load_resistor_ohm / test_load) ** self.load_exponent / np.log(9.0)
            out.append((rise * scale, fall * scale))
        return tuple(np.array(t) for t in zip(*out, strict=True))

    def collector_samples(self, design, light, neighbour, extra, state):
        """Sampled collector currents, A, shape (frames, P, n, 1 or 2): the steady sequence's
        last frame, or with flicker every frame over one period of it.

        ``light`` (P, n): each detector's own LED's collector current when lit; ``neighbour``
        (n,) the neighbour's; ``extra`` (n,): dark and ambient currents."""
        n = light.shape[-1]
        lit, sampled = self.windows(n)
        ahead = np.roll(lit, -1, axis=0)  # the neighbour's pattern, one conversion ahead
        held = lit[:, None] * light + self.neighbour_share * ahead[:, None] * neighbour + extra
        tau_r, tau_f = self.time_constants_s(design)
        t_w, m = 1.0 / self.sample_rate_hz, len(lit)
        per_frame = m * t_w / max(tau_r.max(), tau_f.max())
        settle = int(np.ceil(30.0 / per_frame)) + 1  # e^−30 ≈ 1e-13 of any step
        periods = self.flicker_periods
        record = int(np.ceil(periods / (state.flicker_hz * m * t_w))) if state.flicker_a else 1
        steps = self.substeps if state.flicker_a else 1
        dt = t_w / steps
        state_i = held.mean(axis=0)
        frames = []
        for frame in range(settle + record):
            ends = []
            for w in range(m):
                for s in range(steps):
                    t = ((frame * m + w) * steps + s + 0.5) * dt
                    u = held[w] + state.flicker_a * np.sin(2.0 * np.pi * state.flicker_hz * t)
                    tau = np.where(u > state_i, tau_r, tau_f)
                    state_i = u + (state_i - u) * np.exp(-dt / tau)
                ends.append(state_i)
            if frame >= settle:
                ends = np.stack(ends)  # (m, P, n)
                per_sensor = [ends[sampled[k], :, k] for k in range(n)]  # (reads, P) each
                frames.append(np.stack(per_sensor).transpose(2, 0, 1))
        return np.stack(frames)

    def readings(self, design, circuit, eta, neighbour, state):
        """Readings (P, n), V, of couplings η under this read-out (:func:`_circuit` constants;
        with flicker, the frame whose outputs it lowers most on average)."""
        light = circuit["gain"] * eta
        samples = self.collector_samples(design, light, neighbour, circuit["extra"], state)
        v_out = np.clip(
            circuit["vcc"][:, None] - circuit["r2"][:, None] * samples,
            circuit["vsat"][:, None],
            circuit["vcc"][:, None],
        )
        volts = circuit["scale"][:, None] * v_out
        if self.scheme == "modulated":
            volts = np.array([m.supply_v for m in design.models]) - volts[..., 1] + volts[..., 0]
        else:
            volts = volts[..., 0]
        if len(volts) == 1:
            return volts[0]
        steady = self.readings(
            design, circuit, eta, neighbour, dataclasses.replace(state, flicker_a=0.0)
        )
        return volts[np.argmin(np.mean(volts - steady, axis=(1, 2)))]
