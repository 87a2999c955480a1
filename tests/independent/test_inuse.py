"""Hand-computed checks of the independent in-use truth (tests/independent/inuse.py).

Every expected value here is arithmetic written out in the test from the circuit's formulas and
the transcribed datasheet points, with η taken from ``direct_response``; nothing is compared
with the package's error budget.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.design._design import load_design
from reflector_opt.model._reference import direct_response
from tests.independent import inuse
from tests.independent.inuse import InUse

DESIGN_FILE = Path(__file__).resolve().parents[2] / "examples" / "data" / "design.json"

#: A few poses inside the workspace (±15°), degrees.
PITCH = np.array([0.0, 7.5, -12.0, 14.0])
ROLL = np.array([0.0, -4.0, 11.0, -14.0])


@pytest.fixture(scope="module")
def design():
    """examples/data/design.json (two NJL5901R-2 sensors)."""
    return load_design(DESIGN_FILE)


@pytest.fixture(scope="module")
def vcnt_design(design):
    """The same geometry with VCNT2020 sensors (the catalogue's part)."""
    sensors = tuple(dataclasses.replace(s, model="VCNT2020") for s in design.sensors)
    return design.replace(sensors=sensors)


def _fixed_point_led_current(vcc, vf_offset, model, s):
    """I_F = (Vcc − [V_F,nom + vf_offset + s · ln(I_F / I_nom)]) / R1 by 60 fixed-point steps
    (the map contracts by s / (R1 · I_F) ≈ 0.025)."""
    i_nom = (model.supply_v - model.led_forward_v) / model.led_resistor_ohm
    i = i_nom
    for _ in range(60):
        vf = model.led_forward_v + vf_offset + s * np.log(i / i_nom)
        i = (vcc - vf) / model.led_resistor_ohm
    return i


# -- the nominal state and the inversion ------------------------------------------------------


def test_zero_state_gives_zero_error(design):
    error = inuse.in_use_error_deg(design, PITCH, ROLL, InUse())
    assert error.shape == (len(PITCH), 2)
    assert np.abs(error).max() < 1e-6


def test_inversion_recovers_a_known_pose_from_a_distant_start(design):
    volts = inuse.readings(design, PITCH, ROLL)
    start = np.stack([PITCH, ROLL], axis=-1) + np.array([2.0, -2.0])
    angles = inuse.read_angles(design, volts, start)
    assert_allclose(angles, np.stack([PITCH, ROLL], axis=-1), atol=1e-7)


def test_inversion_from_one_start_for_all_poses(design):
    volts = inuse.readings(design, PITCH[:2], ROLL[:2])
    angles = inuse.read_angles(design, volts, (0.0, 0.0))
    assert_allclose(angles, np.stack([PITCH[:2], ROLL[:2]], axis=-1), atol=1e-7)


# -- the circuit by hand ----------------------------------------------------------------------


def test_circuit_by_hand_at_calibration(design):
    """At 25 °C and the nominal supply V_F = led_forward_v exactly (the log term is zero), so
    I_F = (3.3 − 1.2) / 680 A, I_C = G·η·I_F + I_CEO(25 °C) (10 nA assumed for the NJL5901R-2)
    and the reading is Vcc − R2·I_C."""
    _, eta, volts_dr = direct_response(design, PITCH, ROLL)
    model = design.models[0]
    assert (model.supply_v, model.led_forward_v, model.led_resistor_ohm) == (3.3, 1.2, 680.0)
    i_f = (3.3 - 1.2) / 680.0
    i_c = model.current_gain * eta * i_f + model.dark_current_a + 10e-9
    expected = 3.3 - model.load_resistor_ohm * i_c
    got = inuse.readings(design, PITCH, ROLL)
    assert_allclose(got, expected, rtol=0, atol=1e-12)
    # and the package's own nominal volts differ by the dark current this module adds only
    assert_allclose(got, volts_dr - model.load_resistor_ohm * 10e-9, rtol=0, atol=1e-9)


def test_circuit_by_hand_with_a_temperature_gradient(design):
    """S1 10 K warmer, S2 unchanged, with a linear k(T) of +0.4 %/K: on S1 k = 1.04,
    V_F = 1.2 − 1.5 mV/K · 10 K + s·ln(I_F/I_nom) (solved by fixed point), I_dark =
    10 nA · 2^(10/8); S2 reads as at calibration."""
    state = InUse(delta_t_k=(10.0, 0.0), linear_output_per_k=0.004)
    pitch, roll = PITCH[1:2], ROLL[1:2]
    _, eta, _ = direct_response(design, pitch, roll)
    model = design.models[0]
    s = 2.0 * 1.380649e-23 * 298.15 / 1.602176634e-19
    i_f = _fixed_point_led_current(3.3, -1.5e-3 * 10.0, model, s)
    assert 1e-6 < i_f / ((3.3 - 1.2) / 680.0) - 1 < 0.01  # V_F fell, so I_F rose a little
    i_c = model.current_gain * eta[0, 0] * i_f * 1.04 + 10e-9 * 2.0 ** (10.0 / 8.0)
    warm = 3.3 - model.load_resistor_ohm * i_c
    got = inuse.readings(design, pitch, roll, state)
    nominal = inuse.readings(design, pitch, roll)
    assert_allclose(got[0, 0], warm, rtol=0, atol=1e-12)
    assert got[0, 1] == nominal[0, 1]


def test_supply_change_fixed_and_ratiometric_by_hand(design):
    """Vcc + 10 mV: I_F from the fixed point at 3.31 V; V_out = 3.31 − R2·I_C; a fixed
    reference reads V_out, a ratiometric one V_out · 3.3 / 3.31."""
    pitch, roll = PITCH[2:3], ROLL[2:3]
    _, eta, _ = direct_response(design, pitch, roll)
    model = design.models[0]
    s = 2.0 * 1.380649e-23 * 298.15 / 1.602176634e-19
    i_f = _fixed_point_led_current(3.31, 0.0, model, s)
    v_out = 3.31 - model.load_resistor_ohm * (model.current_gain * eta[0] * i_f + 10e-9)
    fixed = inuse.readings(design, pitch, roll, InUse(supply_change_v=0.010))
    ratio = inuse.readings(
        design, pitch, roll, InUse(supply_change_v=0.010, adc_reference="ratiometric")
    )
    assert_allclose(fixed[0], v_out, rtol=0, atol=1e-12)
    assert_allclose(ratio[0], v_out * 3.3 / 3.31, rtol=0, atol=1e-12)
    # I_F rises by about ΔVcc / (R1 + s / I_F): first-order check of the root
    i_nom = 2.1 / 680.0
    assert_allclose(i_f - i_nom, 0.010 / (680.0 + s / i_nom), rtol=1e-3)


def test_ambient_current_lowers_one_output_by_r2_times_it(design):
    state = InUse(ambient_a=(1e-6, 0.0))
    got = inuse.readings(design, PITCH, ROLL, state)
    nominal = inuse.readings(design, PITCH, ROLL)
    r2 = design.models[0].load_resistor_ohm
    assert_allclose(nominal[:, 0] - got[:, 0], r2 * 1e-6, rtol=0, atol=1e-12)
    assert_allclose(got[:, 1], nominal[:, 1], rtol=0, atol=0)


def test_output_clips_at_saturation_and_supply(design):
    sat = design.models[0].saturation_v
    low = inuse.readings(design, PITCH[:1], ROLL[:1], InUse(ambient_a=1.0))  # 1 A: saturated
    assert_allclose(low, sat)
    high = inuse.readings(design, PITCH[:1], ROLL[:1], InUse(ambient_a=-1.0))  # no current
    assert_allclose(high, design.models[0].supply_v)


# -- the transcribed figures and their interpolants --------------------------------------------


@pytest.mark.parametrize("name", ["VCNT2020", "TCRT5000", "CNY70"])
def test_relative_output_interpolant_reproduces_the_read_off_points(name):
    part = inuse.PARTS[name]
    table = part.relative_output
    t = np.array(table.temperature_c)
    raw = np.array(table.values)
    assert_allclose(table.spline()(t), raw, rtol=0, atol=1e-12)
    c25 = table.spline()(25.0)
    assert_allclose(inuse.relative_output(part, t, 25.0), raw / c25, rtol=1e-12)
    assert inuse.relative_output(part, 25.0, 25.0) == pytest.approx(1.0, abs=1e-15)
    assert inuse.relative_output(part, 40.0, 40.0) == pytest.approx(1.0, abs=1e-15)
    assert "Fig." in table.source


def test_relative_output_slopes_follow_the_read_off_points():
    """The spline's slope at 25 °C lies near the chord of the neighbouring read-off points:
    VCNT2020 0 → 50 °C 0.38 %/K (figures.md: +0.40 %/K fitted), TCRT5000 20 → 30 °C 0.18 %/K
    and CNY70 20 → 30 °C 0.10 %/K. (The TCRT5000's local slope is about twice the +0.10 %/K
    of figures.md's quadratic fit over −25…100 °C: the points themselves rise 1.8 % from 20
    to 30 °C.) The domes peak near 40 and 45 °C."""
    h = 0.5
    for name, slope, tol in (
        ("VCNT2020", 0.0038, 0.0005),
        ("TCRT5000", 0.0018, 0.0005),
        ("CNY70", 0.0010, 0.0005),
    ):
        k = inuse.relative_output(inuse.PARTS[name], np.array([25.0 - h, 25.0 + h]))
        assert abs((k[1] - k[0]) / (2 * h) - slope) < tol, name
    t = np.linspace(0.0, 75.0, 751)
    assert 35 <= t[np.argmax(inuse.relative_output(inuse.PARTS["TCRT5000"], t))] <= 45
    assert 38 <= t[np.argmax(inuse.relative_output(inuse.PARTS["CNY70"], t))] <= 50


def test_relative_output_refuses_temperatures_outside_the_curve():
    with pytest.raises(ValueError, match="outside the published range"):
        inuse.relative_output(inuse.PARTS["CNY70"], 90.0)


def test_forward_voltage_interpolant_reproduces_the_read_off_points(vcnt_design):
    part = inuse.PARTS["VCNT2020"]
    table = part.forward_voltage
    t = np.array(table.temperature_c)
    assert_allclose(table.spline()(t), table.values, rtol=0, atol=1e-12)
    model = vcnt_design.models[0]
    i_nom = (model.supply_v - model.led_forward_v) / model.led_resistor_ohm
    # at the nominal current V_F follows the published curve's shape from led_forward_v
    for temp, value in zip(table.temperature_c, table.values, strict=True):
        got = inuse.forward_voltage_v(part, model, temp, i_nom)
        assert got == pytest.approx(model.led_forward_v + value - 1.243, abs=1e-12)
    # the slope about 25 °C is the published TK_VF, −1.0 mV/K (±0.1)
    slope = (
        inuse.forward_voltage_v(part, model, 26.0, i_nom)
        - inuse.forward_voltage_v(part, model, 24.0, i_nom)
    ) / 2.0
    assert -1.1e-3 < slope < -0.9e-3
    # s: LSQ of 1.205/1.243/1.316 V against ln(10/20/50 mA)
    ln_i = np.log([0.01, 0.02, 0.05])
    v = np.array([1.205, 1.243, 1.316])
    s = np.sum((ln_i - ln_i.mean()) * (v - v.mean())) / np.sum((ln_i - ln_i.mean()) ** 2)
    assert part.forward_voltage_per_ln_current == pytest.approx(s, rel=1e-12)
    # the line in ln I_F misses the 25 °C points by ≤ 12 mV (the curve bends up at 50 mA)
    for current, other in inuse.VCNT2020_VF_OTHER_CURRENTS.items():
        assert other.values[2] == pytest.approx(1.243 + s * np.log(current / 0.02), abs=0.012)


def test_vcnt2020_dark_current_doubling_fits_its_curve():
    part = inuse.PARTS["VCNT2020"]
    curve = inuse.VCNT2020_DARK_CURVE
    predicted = part.dark_current_25c_a * 2.0 ** ((np.array(curve.temperature_c) - 25.0) / 6.5)
    assert np.all(np.abs(np.log(predicted / np.array(curve.values))) < np.log(2.0))
    assert part.dark_doubling_k == pytest.approx(6.49, abs=0.01)


def test_part_without_a_curve_needs_a_stated_coefficient(design):
    with pytest.raises(ValueError, match="linear_output_per_k"):
        inuse.readings(design, PITCH[:1], ROLL[:1], InUse(delta_t_k=5.0))


def test_vcnt2020_curve_used_for_a_warm_unit(vcnt_design):
    """+5 K on a VCNT2020 unit: k from the curve, I_F from the V_F curve at 30 °C."""
    pitch, roll = PITCH[1:2], ROLL[1:2]
    _, eta, _ = direct_response(vcnt_design, pitch, roll)
    model = vcnt_design.models[0]
    part = inuse.PARTS["VCNT2020"]
    spline_vf = part.forward_voltage.spline()
    i_f = _fixed_point_led_current(
        3.3, float(spline_vf(30.0) - spline_vf(25.0)), model, part.forward_voltage_per_ln_current
    )
    spline_k = part.relative_output.spline()
    k = float(spline_k(30.0) / spline_k(25.0))
    dark = 1e-9 * 2.0 ** (5.0 / part.dark_doubling_k)
    expected = 3.3 - model.load_resistor_ohm * (model.current_gain * eta[0] * i_f * k + dark)
    got = inuse.readings(vcnt_design, pitch, roll, InUse(delta_t_k=5.0))
    assert_allclose(got[0], expected, rtol=0, atol=1e-12)


# -- the centre shift ---------------------------------------------------------------------------


def test_own_geometry_reproduces_direct_response_distances(design):
    d_dr, _, _ = direct_response(design, PITCH, ROLL)
    assert_allclose(inuse.eq3_distance_mm(design, PITCH, ROLL), d_dr, rtol=0, atol=1e-12)


def test_zero_shift_design_reproduces_direct_response_exactly(design):
    d_dr, eta_dr, _ = direct_response(design, PITCH, ROLL)
    for i, (p, r) in enumerate(zip(PITCH, ROLL, strict=True)):
        same = inuse.shifted_design(design, p, r, (0.0, 0.0, 0.0))
        d, eta, _ = direct_response(same, p, r)
        assert_allclose(d, d_dr[i], rtol=0, atol=1e-13)
        assert_allclose(eta, eta_dr[i], rtol=1e-13, atol=0)


def test_shifted_centre_lands_where_the_base_frame_shift_puts_it(design):
    """R · (s0 + Rᵀδ) = R · s0 + δ, and direct_response's distances with the shifted design
    equal |f − (R · s0 + δ)| − r_s from the own geometry, at rotated poses."""
    delta = np.array([0.03, -0.02, 0.05])
    rot = inuse.rotation_matrix(PITCH, ROLL)
    moved = inuse.centre_in_rotating_frame(design, PITCH, ROLL, delta)
    s0 = np.array(design.reflector.centre_mm)
    assert_allclose(np.einsum("pij,pj->pi", rot, moved), rot @ s0 + delta, atol=1e-14)
    _, d = inuse.coupling(design, PITCH, ROLL, delta, distance=True)
    assert_allclose(d, inuse.eq3_distance_mm(design, PITCH, ROLL, delta), rtol=0, atol=1e-12)


def test_rotation_convention_is_rx_times_ry():
    """Pitch +90° takes x to −z (about y); roll +90° takes y to +z (about x)."""
    assert_allclose(inuse.rotation_matrix(90.0, 0.0) @ [1.0, 0, 0], [0, 0, -1.0], atol=1e-15)
    assert_allclose(inuse.rotation_matrix(0.0, 90.0) @ [0, 1.0, 0], [0, 0, 1.0], atol=1e-15)
    # R = Rx(α)·Ry(γ): pitch first, then roll
    r = inuse.rotation_matrix(90.0, 90.0)
    assert_allclose(r @ [1.0, 0, 0], [0, 1.0, 0], atol=1e-15)  # x → −z → +y


@pytest.mark.parametrize("k", [0, 1])
def test_shift_along_a_sensor_axis_changes_its_distance_to_first_order(design, k):
    """δ = ε·a (a the sensor's optical axis, toward the reflector): Δd = −p̂·δ + O(ε²/|p|),
    p = f − R·s0; a is nearly −p̂ here, so the sphere moving along a moves away by ≈ ε."""
    eps = 1e-4
    axis = np.array(design.sensors[k].axis) / np.linalg.norm(design.sensors[k].axis)
    pitch, roll = PITCH[1:3], ROLL[1:3]
    d0, _, _ = direct_response(design, pitch, roll)
    _, d1 = inuse.coupling(design, pitch, roll, eps * axis, distance=True)
    f = np.array(design.sensors[k].position_mm)
    p = f - inuse.rotation_matrix(pitch, roll) @ np.array(design.reflector.centre_mm)
    p_hat = p / np.linalg.norm(p, axis=-1, keepdims=True)
    expected = -eps * p_hat @ axis
    assert_allclose(d1[:, k] - d0[:, k], expected, rtol=0, atol=eps**2)
    assert np.all(expected > 0.9 * eps)


def test_common_warming_of_a_symmetric_unit_reads_as_pitch_only(design):
    """The example design is mirror-symmetric in y (S2 is S1 mirrored): at roll 0 a common gain
    change keeps V1 = V2, so the unit reads a roll of 0 and only a pitch error."""
    pitch = np.array([-10.0, 0.0, 10.0])
    error = inuse.in_use_error_deg(
        design, pitch, np.zeros(3), InUse(delta_t_k=5.0, linear_output_per_k=0.004)
    )
    assert np.abs(error[:, 1]).max() < 1e-8
    assert np.abs(error[:, 0]).min() > 1e-3


def test_small_state_error_matches_the_own_linearisation(design):
    """For a small change the error e solves J · e = ΔV (J the nominal readings' central
    difference Jacobian, V/°): the nonlinear inversion agrees to a few per cent."""
    pitch, roll = np.array([5.0]), np.array([-5.0])
    state = InUse(delta_t_k=1.0, linear_output_per_k=0.004)
    dv = (inuse.readings(design, pitch, roll, state) - inuse.readings(design, pitch, roll))[0]
    h = 1e-3
    jac = np.stack(
        [
            (inuse.readings(design, pitch + h, roll) - inuse.readings(design, pitch - h, roll))[0],
            (inuse.readings(design, pitch, roll + h) - inuse.readings(design, pitch, roll - h))[0],
        ],
        axis=-1,
    ) / (2 * h)
    linear = np.linalg.solve(jac, dv)
    error = inuse.in_use_error_deg(design, pitch, roll, state)[0]
    assert_allclose(error, linear, rtol=0.03, atol=2e-3)
    assert np.abs(error).max() > 0.05


def test_the_generator_imports_none_of_the_budgets_code():
    """tests/independent/inuse.py imports nothing of the budget or of the fast model's circuit,
    temperature, operating point, kernel or interpolation."""
    import ast

    source = Path(inuse.__file__).read_text(encoding="utf-8")
    imported = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            imported.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            imported.add(node.module or "")
            imported.update(f"{node.module}.{alias.name}" for alias in node.names)
    model_parts = ("forward", "temperature", "operating", "electronics", "kernel", "interpolation")
    forbidden = ("reflector_opt.analysis", *(f"reflector_opt.model.{m}" for m in model_parts))
    reflector = {name for name in imported if name.startswith("reflector_opt")}
    assert reflector == {
        "reflector_opt.model._reference",
        "reflector_opt.model._reference.direct_response",
    }
    assert not any(name.startswith(forbidden) for name in imported)


def _settled(design, state=None):
    """η at PITCH, ROLL and the circuit's constants of ``state`` (calibration by default)."""
    circuit = inuse._circuit(design, state or InUse(), 25.0)
    return inuse.coupling(design, PITCH, ROLL), circuit


def test_time_constants_by_hand(design, vcnt_design):
    """τ = t / ln 9 · (R2 / R_test)^p: 40 µs at 100 Ω for the NJL5901R-2, 10 / 15 µs for the
    VCNT2020, p = 0.5 here."""
    drive = inuse.Drive("multiplexed", load_exponent=0.5)
    for d, (rise, fall) in ((design, (40e-6, 40e-6)), (vcnt_design, (10e-6, 15e-6))):
        scale = np.sqrt(d.models[0].load_resistor_ohm / 100.0) / np.log(9.0)
        assert_allclose(drive.time_constants_s(d), ([rise * scale] * 2, [fall * scale] * 2))


@pytest.mark.parametrize("scheme", ["dc", "multiplexed", "modulated"])
def test_own_light_kept_under_each_drive_by_hand(vcnt_design, scheme):
    """One LED window of M, rising with r_r = exp(−t_w/τ_r) and falling with r_f per window:
    the periodic state at the end of the lit window is a·(1 − r_r)/(1 − r_r·r_f^(M−1)) over
    the dark level; ``modulated`` keeps that less its fall over the dark window after it;
    ``dc`` keeps all. The ambient and dark currents pass whole."""
    eta, circuit = _settled(vcnt_design, InUse(ambient_a=2e-7))
    drive = inuse.Drive(scheme, sample_rate_hz=20000.0)
    tau_r, tau_f = drive.time_constants_s(vcnt_design)
    r_r, r_f = np.exp(-5e-5 / tau_r), np.exp(-5e-5 / tau_f)
    m = {"dc": 2, "multiplexed": 2, "modulated": 4}[scheme]
    share = (1 - r_r) / (1 - r_r * r_f ** (m - 1))
    share = {"dc": 1.0, "multiplexed": share, "modulated": share * (1 - r_f)}[scheme]
    light = circuit["gain"] * eta
    expected = circuit["vcc"] - circuit["r2"] * (
        share * light + circuit["extra"] * (scheme != "modulated")
    )
    got = drive.readings(vcnt_design, circuit, eta, np.zeros(2), InUse(ambient_a=2e-7))
    assert_allclose(got, expected, rtol=0, atol=1e-12)


@pytest.mark.parametrize("scheme", ["multiplexed", "modulated"])
def test_the_neighbour_s_light_the_window_before_is_left_at_r(design, scheme):
    """Symmetric τ: the neighbour's light c·P, lit the window before the unit's own, reaches
    the sample as r·c·P times the own light's share G, so relative to the own light r·c."""
    eta, circuit = _settled(design)
    drive = inuse.Drive(scheme, neighbour_share=0.01)
    tau = drive.time_constants_s(design)[0]
    r = np.exp(-1e-4 / tau)
    m = {"multiplexed": 2, "modulated": 4}[scheme]
    g = (1 - r) / (1 - r**m) * ((1 - r) if scheme == "modulated" else 1.0)
    p = np.array([1e-5, 2e-5])
    base = drive.readings(design, circuit, eta, np.zeros(2), InUse())
    lit = drive.readings(design, circuit, eta, p, InUse())
    expected = np.broadcast_to(circuit["r2"] * r * g * 0.01 * p, base.shape)
    assert_allclose(base - lit, expected, rtol=1e-9)


def test_flicker_under_dc_is_the_detector_s_low_pass_at_its_worst_frame(design):
    """``dc``, 0.5 µA of 100 Hz flicker: the output falls at most by R2·A/√(1 + (ωτ)²) (the
    first-order low pass), the frame the truth picks within a frame's phase step of it."""
    eta, circuit = _settled(design)
    drive = inuse.Drive("dc")
    tau = drive.time_constants_s(design)[0][0]
    amplitude, w = 5e-7, 2 * np.pi * 100.0
    state = InUse(flicker_a=amplitude)
    drop = drive.readings(design, circuit, eta, np.zeros(2), InUse()) - drive.readings(
        design, circuit, eta, np.zeros(2), state
    )
    peak = circuit["r2"][0] * amplitude / np.hypot(1.0, w * tau)
    step = w * 2 / 1e4  # a frame of two conversions
    assert np.all(drop <= peak * (1 + 1e-6)) and np.all(drop >= peak * np.cos(step))
