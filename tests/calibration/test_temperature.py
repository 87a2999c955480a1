"""Temperature compensation: the inversion, the thermal parameters and their std, built units."""

import dataclasses
import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.calibration._coefficients import (
    load_model,
    model_from_dict,
    model_to_dict,
    save_model,
)
from reflector_opt.calibration._models import make_model
from reflector_opt.calibration._plans import make_plan
from reflector_opt.calibration._simulation import measure_with_design_noise
from reflector_opt.calibration._temperature import (
    TemperatureCompensated,
    check_temperatures,
    compensate,
)
from reflector_opt.calibration._validation import cross_validate
from reflector_opt.model._forward import voltages
from reflector_opt.model._noise import Mismatch
from reflector_opt.model._operating import OperatingState, apply_state
from reflector_opt.model._temperature import (
    ThermalCoefficients,
    dark_current_a,
    photocurrent_factor,
)
from reflector_opt.tolerance._builtunit import build_unit, crlb_floor_deg
from reflector_opt.util._errors import InputError
from reflector_opt.util._seeds import stream_rng

#: Two parts whose light paths drift differently, neither the generic coefficients.
DIFFERENT = (
    ThermalCoefficients(led_output_per_k=-0.008, detector_gain_per_k=0.001, dark_current_a=2e-7),
    ThermalCoefficients(
        led_output_per_k=-0.003,
        detector_gain_per_k=0.003,
        forward_voltage_v_per_k=-0.0015,
        dark_current_a=5e-8,
        dark_doubling_k=8.0,
    ),
)


# --- the inversion ---------------------------------------------------------------------------


def test_compensation_by_hand():
    # V0 = 3.3 − (3.3 − 2.0 − 0.0005·10) / (1 − 0.002·10) = 3.3 − 1.295 / 0.98
    v0 = compensate([[2.0, 2.0]], [10.0], [-0.002, 0.0], [0.0005, 0.0], 3.3)
    assert_allclose(v0, [[3.3 - 1.295 / 0.98, 2.0]], rtol=1e-15)
    # and Eq 1 forward again: V = Vcc − (Vcc − V0)(1 + cΔT) − dΔT
    assert_allclose(3.3 - (3.3 - v0[0, 0]) * (1 - 0.02) - 0.005, 2.0, rtol=1e-15)
    # no change at the reference temperature, whatever the coefficients
    assert_allclose(compensate([[1.7, 2.9]], [0.0], [0.01, -0.01], [0.1, 0.1], 3.3), [[1.7, 2.9]])


def test_compensation_undoes_the_light_path_of_the_model(design):
    """An independent path: the pipeline's temperature term with the growth of its dark current
    cancelled (LED on/off differencing) is Eq 1 with c = (F − 1)/ΔT and d = −R2·I_dark·c,
    I_dark the part the sensor model reads with no light."""
    model = dataclasses.replace(design.models[0], dark_current_a=3e-6)
    thermal, dt = DIFFERENT[0], 7.5
    volts = np.linspace(0.6, 3.1, 11)
    state = OperatingState(delta_t_k=dt, thermal=thermal, dark_current_changes=False)
    warm = apply_state(volts[:, None], (model,), state)[:, 0]
    c = (photocurrent_factor(dt, thermal, model) - 1.0) / dt
    d = -model.load_resistor_ohm * model.dark_current_a * c
    back = compensate(warm[:, None], np.full(11, dt), [c], [d], model.supply_v)
    assert_allclose(back[:, 0], volts, atol=1e-12)
    assert np.abs(warm - volts).max() > 0.05  # 7.5 K moves them by tens of mV


def test_a_temperature_that_reverses_the_light_is_refused():
    with pytest.raises(InputError, match="temperature_c"):
        compensate([[2.0, 2.0]], [100.0], [-0.02, 0.0], [0.0, 0.0], 3.3)


# --- the thermal parameters against known ones -----------------------------------------------


def _two_temperature_truth(model, thermal, temps_c, reference_c, gain, offset_v):
    """c and d of Eq 1 that model.temperature's physics obeys exactly at two temperatures
    (the module notes of calibration.temperature), for a read-out gain and offset.

    Vcc − V_read(T_i) = g·(u·F_i + D_i) + K with u = Vcc − V at 20 °C, F_i the photocurrent
    factor, D_i = R2·(I_m·(1 − F_i) + I_dark(T_i) − I_dark(20 °C)) (I_m the model's own dark
    current, I_dark the part's thermal one) and K = Vcc·(1 − g) − o; Eq 1 needs
    (s·u + t)(1 + c·Δ_i) + d·Δ_i for all u: c from F_1 (1 + c·Δ_2) = F_2 (1 + c·Δ_1), then
    t and d from the two constant terms.
    """
    vcc, r2 = model.supply_v, model.load_resistor_ohm
    rise = [t - 20.0 for t in temps_c]
    delta = [t - reference_c for t in temps_c]
    f = [float(photocurrent_factor(x, thermal, model)) for x in rise]
    c = (f[1] - f[0]) / (f[0] * delta[1] - f[1] * delta[0])
    growth = [float(dark_current_a(x, thermal) - dark_current_a(0.0, thermal)) for x in rise]
    constant = [
        gain * r2 * (model.dark_current_a * (1.0 - fi) + g) + vcc * (1.0 - gain) - offset_v
        for fi, g in zip(f, growth, strict=True)
    ]
    matrix = [[1.0 + c * delta[0], delta[0]], [1.0 + c * delta[1], delta[1]]]
    _, d = np.linalg.solve(matrix, constant)
    return c, d


def test_known_coefficients_are_recovered_within_their_std(design):
    """Fast-model voltages through model.temperature's light path (different parts, a read-out
    gain and offset, the design's noise) at 20 °C and 32 °C; the fit sees volts, angles and
    temperatures only."""
    mismatch = Mismatch(gain=(0.97, 1.02), offset_v=(0.01, -0.006))
    fitted = _synthetic_fit(design, mismatch, 300, np.random.default_rng(4))
    assert fitted.reference_temperature_c_ == pytest.approx(26.0)
    for k, model in enumerate(design.models):
        c, d = _two_temperature_truth(
            model, DIFFERENT[k], (20.0, 32.0), 26.0, mismatch.gain[k], mismatch.offset_v[k]
        )
        assert abs(fitted.gain_per_k_[k] - c) < 3 * fitted.gain_per_k_std_[k]
        assert abs(fitted.offset_v_per_k_[k] - d) < 3 * fitted.offset_v_per_k_std_[k]
        assert fitted.gain_per_k_std_[k] < 1e-4  # 0.01 %/K: determined, not only uncertain
    assert fitted.gain_per_k_[0] < fitted.gain_per_k_[1] - 0.005  # the parts told apart


def _synthetic_fit(design, mismatch, n, rng, form="poly6"):
    """A compensated fit to fast-model data at 20 °C and 32 °C through model.temperature's
    light path (DIFFERENT parts, a read-out gain and offset, the design's noise)."""
    poses = rng.uniform(-15, 15, (2 * n, 2))
    clean = voltages(design, poses[:, 0], poses[:, 1])
    temperature = np.repeat([20.0, 32.0], n)
    hot = OperatingState(delta_t_k=12.0, thermal=DIFFERENT)
    warm = np.concatenate([clean[:n], apply_state(clean[n:], design.models, hot)])
    read = measure_with_design_noise(design, mismatch.apply(warm), rng)
    return TemperatureCompensated(form).fit(read, poses, temperature)


def test_the_stated_std_matches_the_scatter_over_noise_draws(design):
    """z = (fitted − true) / std over 12 noise draws, 4 parameters each: centred, about unit
    spread (measured: mean 0.02, standard deviation 1.20)."""
    mismatch = Mismatch(gain=(1.01, 0.98), offset_v=(-0.004, 0.012))
    truth = [
        _two_temperature_truth(
            m, DIFFERENT[k], (20.0, 32.0), 26.0, mismatch.gain[k], mismatch.offset_v[k]
        )
        for k, m in enumerate(design.models)
    ]
    z = []
    for seed in range(12):
        fitted = _synthetic_fit(design, mismatch, 150, np.random.default_rng(200 + seed), "poly5")
        for k, (c, d) in enumerate(truth):
            z.append((fitted.gain_per_k_[k] - c) / fitted.gain_per_k_std_[k])
            z.append((fitted.offset_v_per_k_[k] - d) / fitted.offset_v_per_k_std_[k])
    assert abs(np.mean(z)) < 0.5 and 0.5 < np.std(z) < 1.4, (np.mean(z), np.std(z))


# --- built units: exact optics, as-built geometry, read-out, noise ---------------------------


@pytest.fixture(scope="module")
def units(design):
    return [build_unit(design, i, seed=5) for i in range(2)]


def _rms(error):
    return np.sqrt(np.mean(error**2, axis=0))


@pytest.mark.parametrize(
    "thermal", [ThermalCoefficients(), DIFFERENT], ids=["generic", "per-sensor"]
)
def test_built_units_calibrated_at_two_temperatures_hold_their_accuracy_between(
    design, units, thermal
):
    """Calibrated at T0 (100-pose grid) and T0 + 10 K (40 Sobol poses), validated at T0 + 5 K:
    within 1.5× the unit's white-noise error at T0 (the form fitted at T0, validated there
    with the same noise draws), while that form used at T0 + 5 K is far off."""
    base = make_plan(design.workspace, "grid", 100)
    warm_poses = make_plan(design.workspace, "sobol", 40, seed=2)
    for unit in units:
        rng = stream_rng(5, "thermal_plan", unit.index)  # as benchmarks/temperature_calibration.py
        cold = unit.record(base, rng)
        warm = unit.record(warm_poses, rng, state=OperatingState(delta_t_k=10.0, thermal=thermal))
        truth = stream_rng(5, "thermal_truth_poses", unit.index).uniform(-15, 15, (2000, 2))

        def validate(dt, unit=unit, truth=truth):  # the same noise draws at each temperature
            state = OperatingState(delta_t_k=dt, thermal=thermal)
            noise = stream_rng(5, "thermal_truth_noise", unit.index)
            return unit.record(truth, noise, 0.0, state).volts

        at_t0, at_5k = validate(0.0), validate(5.0)
        plain = make_model("poly5").fit(cold.volts, cold.angles_deg)
        white = _rms(plain.predict(at_t0) - truth)
        compensated = TemperatureCompensated("poly5").fit(
            np.vstack([cold.volts, warm.volts]),
            np.vstack([cold.angles_deg, warm.angles_deg]),
            np.r_[np.full(len(base), 25.0), np.full(len(warm_poses), 35.0)],
        )
        comp_5k = _rms(compensated.predict(at_5k, np.full(len(truth), 30.0)) - truth)
        comp_t0 = _rms(compensated.predict(at_t0, np.full(len(truth), 25.0)) - truth)
        uncompensated = _rms(plain.predict(at_5k) - truth)
        assert np.all(comp_5k < 1.5 * white), (comp_5k, white)
        assert np.all(comp_5k < 1.5 * crlb_floor_deg(unit, truth)), comp_5k  # the floor itself
        assert np.all(comp_t0 < 1.15 * white), (comp_t0, white)
        # both angles together: one part of DIFFERENT hardly drifts, so one angle may not
        assert np.linalg.norm(uncompensated) > 2.5 * np.linalg.norm(white), uncompensated


def test_built_unit_gain_change_is_the_light_paths_within_its_std(design, units):
    """The fitted c of each sensor against model.temperature's photocurrent factor over the
    two temperatures (exact optics, which the form only approximates)."""
    unit = units[0]
    rng = np.random.default_rng(12)
    poses = make_plan(design.workspace, "sobol", 400, seed=3)
    state = OperatingState(delta_t_k=12.0, thermal=DIFFERENT)
    data = [unit.record(poses, rng), unit.record(poses, rng, state=state)]
    fitted = TemperatureCompensated("poly6").fit(
        np.vstack([s.volts for s in data]),
        np.vstack([s.angles_deg for s in data]),
        np.repeat([20.0, 32.0], len(poses)),
    )
    for k, model in enumerate(unit.design.models):
        c, _ = _two_temperature_truth(model, DIFFERENT[k], (20.0, 32.0), 26.0, 1.0, 0.0)
        assert abs(fitted.gain_per_k_[k] - c) < 3 * fitted.gain_per_k_std_[k]


# --- files, cross-validation, bad input ------------------------------------------------------


@pytest.fixture(scope="module")
def fitted(design, units):
    unit, rng = units[1], np.random.default_rng(3)
    poses = make_plan(design.workspace, "grid", 64)
    state = OperatingState(delta_t_k=8.0)
    data = [unit.record(poses, rng), unit.record(poses, rng, state=state)]
    volts = np.vstack([s.volts for s in data])
    angles = np.vstack([s.angles_deg for s in data])
    temperature = np.repeat([22.0, 30.0], len(poses))
    model = TemperatureCompensated("auto", supply_v=(3.3, 3.25)).fit(volts, angles, temperature)
    return model, volts, angles, temperature


def test_the_coefficient_file_keeps_the_thermal_parameters(fitted, tmp_path):
    model, volts, _, temperature = fitted
    save_model(model, tmp_path / "unit.json")
    loaded = load_model(tmp_path / "unit.json")
    assert isinstance(loaded, TemperatureCompensated) and loaded.name == model.form_.name
    assert_allclose(
        loaded.predict(volts, temperature), model.predict(volts, temperature), atol=1e-10
    )
    block = json.loads((tmp_path / "unit.json").read_text())["temperature"]
    assert block["reference_temperature_c"] == 26.0 and block["supply_v"] == [3.3, 3.25]
    assert block["gain_per_k_std"] == model.gain_per_k_std_.tolist()
    assert block["temperature_range_c"] == [22.0, 30.0]
    plain = {k: v for k, v in model_to_dict(model).items() if k != "temperature"}
    assert not isinstance(model_from_dict(plain), TemperatureCompensated)  # an older file


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("reference_temperature_c", 298.15, "reference_temperature_c: expected a number"),
        ("gain_per_k", [0.01], "gain_per_k: expected"),
        ("offset_v_per_k_std", [-1.0, 0.0], r"offset_v_per_k_std\[0\]"),
    ],
)
def test_a_bad_temperature_block_is_refused_by_name(fitted, key, value, message):
    document = model_to_dict(fitted[0])
    document["temperature"][key] = value
    with pytest.raises(InputError, match=message):
        model_from_dict(document)


def test_cross_validation_refits_the_compensation_per_fold(fitted):
    model, volts, angles, temperature = fitted
    cv = cross_validate(model.fixed_form(), volts, angles, 4, 0, temperature)
    assert cv["folds"] == 4 and np.all(cv["rms_deg"] < 0.3)
    assert np.all(cv["rms_deg"] > model.form_.training_rms_deg_ * 0.9)


@pytest.mark.parametrize(
    ("temperature", "message"),
    [
        (np.full(128, 25.0), "span 0 K"),
        (np.r_[np.full(64, 25.0), np.full(64, 25.6)], "at least 1 K apart"),
        (np.r_[np.full(127, 25.0), np.nan], "sample 127: nan is not finite"),
        (np.full(128, 298.15), "looks like kelvin"),
        (np.full(128, -80.0), "below -60 °C"),
        (np.full(5, 25.0), "expected 128 values"),
    ],
)
def test_bad_temperatures_are_one_line_naming_the_column(fitted, temperature, message):
    _, volts, angles, _ = fitted
    with pytest.raises(InputError, match=message) as error:
        TemperatureCompensated("eq6").fit(volts, angles, temperature)
    assert "temperature_c" in str(error.value) and "\n" not in str(error.value)


def test_the_physical_form_is_not_compensated(design, fitted):
    from reflector_opt.calibration._physical import PhysicalModel

    _, volts, angles, temperature = fitted
    with pytest.raises(InputError, match="not physical"):
        TemperatureCompensated(PhysicalModel(design)).fit(volts, angles, temperature)


def test_temperatures_are_checked_alike_everywhere():
    assert_allclose(check_temperatures([-60.0, 20.5, 150.0]), [-60.0, 20.5, 150.0])
    with pytest.raises(InputError, match=r"temperature_c: sample 1: 151\.0 looks like kelvin"):
        check_temperatures([20.0, 151.0])


# --- a curved gain and a thermometer per sensor ------------------------------------------------


def test_curved_and_per_sensor_compensation_by_hand():
    # sensor 1 at ΔT = 10 K: 3.3 − (3.3 − 2.0 − 0.0005·10) / (1 − 0.002·10 − 5e-5·100)
    # sensor 2 at ΔT = −4 K: 3.3 − (3.3 − 2.5 + 0.001·4) / (1 + 0.003·4 + 1e-4·16)
    v0 = compensate(
        [[2.0, 2.5]], [[10.0, -4.0]], [-0.002, -0.003], [0.0005, 0.001], 3.3, [-5e-5, 1e-4]
    )
    assert_allclose(v0, [[3.3 - 1.295 / 0.975, 3.3 - 0.804 / 1.0136]], rtol=1e-14)
    # one temperature for both (shape P) is the same as the pair (10, 10)
    one = compensate([[2.0, 2.5]], [10.0], [-0.002, -0.003], [0.0005, 0.001], 3.3, [-5e-5, 1e-4])
    pair = compensate(
        [[2.0, 2.5]], [[10.0, 10.0]], [-0.002, -0.003], [0.0005, 0.001], 3.3, [-5e-5, 1e-4]
    )
    assert_allclose(one, pair, rtol=1e-15)


def _curved_data(dt_pair, c=(-0.004, 0.002), q=(-5e-5, -3e-5), d=(2e-4, -1e-4)):
    """Noise-free voltages of an affine unit (V0 = 1.6 + 0.02·(γ, α) + 0.01·(α, γ)) through
    Eq 1 with a curved gain, sensors at ΔT + dt_pair: at T0 − 10, T0, T0 + 10 K, and the
    validation at ΔT = 5 K."""
    grid = np.stack(np.meshgrid(np.linspace(-15, 15, 7), np.linspace(-15, 15, 7)), -1)
    angles = grid.reshape(-1, 2)
    v0 = 1.6 + 0.02 * angles + 0.01 * angles[:, ::-1]

    def at(dt):
        t = dt + np.asarray(dt_pair)
        return 3.3 - (3.3 - v0) * (1 + np.multiply(c, t) + np.multiply(q, t**2)) - np.multiply(d, t)

    temps = np.repeat([15.0, 25.0, 35.0], len(angles))
    volts = np.vstack([at(-10.0), at(0.0), at(10.0)])
    return volts, np.tile(angles, (3, 1)), temps, at(5.0), angles


def test_a_curved_gain_is_learned_with_degree_2_and_left_by_degree_1():
    volts, angles, temps, warm, truth = _curved_data((0.0, 0.0))
    curved = TemperatureCompensated("eq6", reference_temperature_c=25.0, degree=2)
    curved.fit(volts, angles, temps)
    assert_allclose(curved.gain_per_k2_, [-5e-5, -3e-5], rtol=1e-4)
    assert_allclose(curved.gain_per_k_, [-0.004, 0.002], rtol=1e-4)
    assert np.abs(curved.predict(warm, 30.0) - truth).max() < 1e-4
    # linear in ΔT: q·(ΔT² − 2R²/3) left at 5 K (module notes), hundredths of a degree
    linear = TemperatureCompensated("eq6", reference_temperature_c=25.0).fit(volts, angles, temps)
    assert linear.gain_per_k2_ is None
    assert np.abs(linear.predict(warm, 30.0) - truth).max() > 1e-2
    with pytest.raises(InputError, match=r"temperature_c: a gain curved in T .* three"):
        TemperatureCompensated("eq6", degree=2).fit(volts[49:], angles[49:], temps[49:])
    with pytest.raises(InputError, match="degree: 1 or 2"):
        TemperatureCompensated("eq6", degree=3).fit(volts, angles, temps)


def test_a_thermometer_per_sensor_follows_a_gradient_one_thermometer_does_not():
    """Calibrated uniform (one temperature for both), used with S1 0.5 K above and S2 0.5 K
    below the strip's mean: the sensors' own temperatures undo it exactly."""
    volts, angles, temps, _, truth = _curved_data((0.0, 0.0))
    *_, apart, _ = _curved_data((0.5, -0.5))
    model = TemperatureCompensated("eq6", reference_temperature_c=25.0, degree=2)
    model.fit(volts, angles, np.column_stack([temps, temps]))
    own = np.full((len(apart), 2), 30.0) + np.array([0.5, -0.5])
    assert np.abs(model.predict(apart, own) - truth).max() < 1e-4
    assert np.abs(model.predict(apart, 30.0) - truth).max() > 1e-2


def test_a_curved_calibration_file_round_trips():
    volts, angles, temps, warm, _ = _curved_data((0.0, 0.0))
    model = TemperatureCompensated("eq6", degree=2).fit(volts, angles, temps)
    document = json.loads(json.dumps(model_to_dict(model)))
    assert_allclose(document["temperature"]["gain_per_k2"], model.gain_per_k2_, rtol=1e-15)
    back = model_from_dict(document)
    assert_allclose(back.predict(warm, 30.0), model.predict(warm, 30.0), atol=1e-12)
    plain = TemperatureCompensated("eq6").fit(volts, angles, temps)
    assert "gain_per_k2" not in model_to_dict(plain)["temperature"]  # files as before
