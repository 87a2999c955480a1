"""Tolerance model, as-built unit, per-sample analysis, Sobol estimator and the CLI."""

import csv
import dataclasses
import json
import math
import re
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.stats import norm

from reflector_opt.analysis.metrics import evaluate_metrics
from reflector_opt.calibration.models import make_model
from reflector_opt.calibration.simulation import assess, run_protocol
from reflector_opt.cli import main
from reflector_opt.design import Design
from reflector_opt.model.noise import Mismatch
from reflector_opt.tolerance import (
    Job,
    Settings,
    Spread,
    Targets,
    Tolerances,
    as_built,
    draw_sample,
    evaluate_draw,
    sobol_indices,
    supplied,
)
from reflector_opt.tolerance.analysis import evaluate_draws, passes, read_out
from reflector_opt.tolerance.config import parse_tolerance_config
from reflector_opt.tolerance.model import Electrical
from reflector_opt.tolerance.sensitivity import NOISE, check_rows, mix, outside_unit_interval
from reflector_opt.tolerance.study import (
    quantile_upper_bound,
    run_study,
    sobol_summary,
    summarise,
    yield_interval,
)
from reflector_opt.tolerance.sweep import parse_variable, set_value, sweep
from reflector_opt.util.errors import InputError

FAST = Settings(calibration_step_deg=2.0, n_validation=300, metrics_step_deg=2.0)


# --- the model ---------------------------------------------------------------------------------


def test_draw_depends_only_on_seed_and_index():
    a = draw_sample(Tolerances(), 2, seed=7, index=3)
    b = draw_sample(Tolerances.zero(), 2, seed=7, index=3)  # scales do not change the draws
    c = draw_sample(Tolerances(), 2, seed=7, index=4)
    for name in Tolerances.names():
        assert np.array_equal(a.standard[name], b.standard[name])
    assert a.noise_seed == b.noise_seed
    assert not np.array_equal(a.standard["gain"], c.standard["gain"])
    assert a.standard["sensor_position_mm"].shape == (6,)
    assert a.standard["sensor_tilt_deg"].shape == (4,)


def test_uniform_draws_stay_within_their_half_width(design):
    tol = Tolerances(crosstalk_fraction=Spread(0.03, "uniform"))
    coarse = design.replace(workspace=type(design.workspace)(step_deg=1.0))
    values = []
    for i in range(100):
        _, electrical = as_built(coarse, tol, draw_sample(tol, 2, 0, i))
        values.append(electrical.crosstalk_fraction)
    values = np.concatenate(values)
    assert values.min() >= 0 and values.max() <= 0.03  # one-sided: |U(−w, w)|
    assert values.max() > 0.025 and values.min() < 0.005


def test_as_built_hand_values(design):
    tol = Tolerances.zero()
    draw = draw_sample(tol, 2, 0, 0)
    standard = {name: np.zeros_like(v) for name, v in draw.standard.items()}
    standard["reflector_radius_mm"] = np.array([2.0])
    standard["centre_offset_mm"] = np.array([1.0, -1.0, 0.5])
    standard["sensor_position_mm"] = np.array([1.0, 0, 0, 0, -2.0, 0])
    standard["sensor_tilt_deg"] = np.array([1.0, 0, 1.0, 1.0])
    standard["gain"] = np.array([1.0, -1.0])
    standard["crosstalk_fraction"] = np.array([-1.0, 0.5])
    tol = Tolerances(
        **{name: Spread(0.0) for name in Tolerances.names()}
        | {
            "reflector_radius_mm": Spread(0.01),
            "centre_offset_mm": Spread(0.02),
            "sensor_position_mm": Spread(0.05),
            "sensor_tilt_deg": Spread(2.0),
            "gain": Spread(0.03),
            "crosstalk_fraction": Spread(0.01, "uniform"),
        }
    )
    built, electrical = as_built(design, tol, type(draw)(0, standard, draw.noise_seed))
    assert built.reflector.radius_mm == pytest.approx(9.02)
    assert_allclose(built.reflector.centre_mm, (0.02, -0.02, -1.49))
    assert_allclose(built.sensors[0].position_mm, (10.05, 0, 0))
    assert_allclose(built.sensors[1].position_mm, (0, 9.9, 0))

    def angle(a, b):
        a, b = np.asarray(a) / np.linalg.norm(a), np.asarray(b) / np.linalg.norm(b)
        return np.degrees(np.arccos(np.clip(a @ b, -1, 1)))

    assert angle(built.sensors[0].axis, design.sensors[0].axis) == pytest.approx(2.0)
    # two perpendicular tilts of 2°: tan θ = √2 · tan 2°
    expected = np.degrees(np.arctan(math.sqrt(2) * math.tan(math.radians(2.0))))
    assert angle(built.sensors[1].axis, design.sensors[1].axis) == pytest.approx(expected)
    assert electrical.mismatch.gain == pytest.approx((1.03, 0.97))
    assert_allclose(electrical.crosstalk_fraction, [0.01, 0.005])
    multiplexed = as_built(design, Tolerances(multiplexed=True), draw)[1]
    assert np.all(multiplexed.crosstalk_fraction == 0)


def test_read_out_hand_values(design):
    volts = np.array([[1.0, 2.0], [3.0, 0.5]])
    electrical = Electrical(Mismatch(), np.array([0.1, 0.2]), np.array([10.0, 0.0]))
    # NJL5901R-2: Vcc 3.3 V, R2 10 kΩ, no dark current, V_CE(sat) from the preset
    vsat = design.models[0].saturation_v
    calibration = read_out(design, electrical, volts, in_use=False)
    assert_allclose(
        calibration,
        [[1.0 - 0.1 * 1.3, 2.0 - 0.2 * 2.3], [3.0 - 0.1 * 2.8, max(0.5 - 0.2 * 0.3, vsat)]],
    )
    in_use = read_out(design, electrical, volts, in_use=True)
    assert_allclose(in_use[:, 0], calibration[:, 0] - 10e-6 * 1e4)  # 10 µA · 10 kΩ = 0.1 V
    assert_allclose(in_use[:, 1], calibration[:, 1])
    none = Electrical(Mismatch(), np.zeros(2), np.zeros(2))
    assert np.array_equal(read_out(design, none, volts, in_use=True), volts)


@pytest.mark.parametrize(
    "data, message",
    [
        (
            {"gain": -0.01},
            "tolerances.gain: expected a number from 0 to 1000 or a table, got -0.01",
        ),
        (
            {"crosstalk_fraction": {"scale": -1}},
            "tolerances.crosstalk_fraction.scale: expected a number from 0 to 1000, got -1",
        ),
        (
            {"gain": {"scale": 0.01, "kind": "lognormal"}},
            "tolerances.gain.kind: expected one of 'normal', 'uniform', got 'lognormal'",
        ),
        ({"gian": 0.01}, "[tolerances]: unknown key(s) gian; allowed: reflector_radius_mm"),
        (
            {"gain": {"sigma": 0.01}},
            "[tolerances.gain]: unknown key(s) sigma; allowed: scale, kind",
        ),
        ({"multiplexed": "yes"}, "multiplexed"),
        ({"gain": float("nan")}, "tolerances.gain"),
    ],
)
def test_bad_tolerances(data, message):
    with pytest.raises(InputError, match=re.escape(message)):
        Tolerances.from_dict(data)


def test_bad_settings_and_run_options():
    with pytest.raises(InputError, match=r"settings\.calibration_step_deg"):
        parse_tolerance_config({"settings": {"calibration_step_deg": 0}})
    with pytest.raises(InputError, match=r"run\.samples"):
        parse_tolerance_config({"run": {"samples": 0}})
    with pytest.raises(InputError, match=r"targets\.rms_deg"):
        parse_tolerance_config({"targets": {"rms_deg": -1}})
    with pytest.raises(InputError, match="unknown section"):
        parse_tolerance_config({"tolerance": {}})
    with pytest.raises(InputError, match="model"):
        Settings(model="eq7")
    # the key was lost: 'settings.unknown model 'eq7'; …', 'settings.poly0: the degree …'
    with pytest.raises(InputError, match=r"^settings\.model: unknown model 'eq7'; choose"):
        parse_tolerance_config({"settings": {"model": "eq7"}})
    with pytest.raises(InputError, match=r"^settings\.model: poly0: the degree must be"):
        parse_tolerance_config({"settings": {"model": "poly0"}})
    with pytest.raises(InputError, match=r"^fit: unknown fit 'l1'"):
        Settings(fit="l1")


# --- the analysis of one sample -----------------------------------------------------------------


def test_zero_tolerances_give_the_nominal_design_exactly(design):
    """Independent path: the simulation module's own protocol and the metrics of the design."""
    job = Job(design, Tolerances.zero(), FAST)
    template = make_model("eq6")
    for index in range(3):
        draw = draw_sample(Tolerances(), 2, seed=11, index=index)
        built, _ = as_built(design, Tolerances.zero(), draw)
        assert built == design
        record = evaluate_draw(job, draw)
        protocol = run_protocol(design, step_deg=2.0, n_validation=300, seed=draw.noise_seed)
        reference = assess(template, protocol)
        metrics = evaluate_metrics(design, 2.0)
        assert record["status"] == "ok"
        assert record["rms_pitch_deg"] == reference.total.rms_deg[0]
        assert record["rms_roll_deg"] == reference.total.rms_deg[1]
        assert record["max_pitch_deg"] == reference.total.max_deg[0]
        assert record["max_roll_deg"] == reference.total.max_deg[1]
        assert record["distance_margin_mm"] == metrics.distance_margin_mm.min()
        assert record["resolution_pitch_deg"] == metrics.worst_pitch_deg
        assert record["window_kept"] is True


def test_calibration_absorbs_gain_and_offset_but_not_ambient_light(design):
    """Gain and offset are present in calibration and use: Eq 6 (with a constant term) fitted
    on the unit absorbs most of them. Ambient light in use only is not absorbed."""
    draw = draw_sample(Tolerances(), 2, seed=3, index=0)
    base = evaluate_draw(Job(design, Tolerances.zero(), FAST), draw)
    gain = Tolerances(**_only(gain=Spread(0.05)))
    ambient = Tolerances(**_only(ambient_current_ua=Spread(20.0, "uniform")))
    with_gain = evaluate_draw(Job(design, gain, FAST), draw)
    with_ambient = evaluate_draw(Job(design, ambient, FAST), draw)
    assert with_gain["rms_pitch_deg"] < base["rms_pitch_deg"] + 0.05
    assert with_ambient["rms_pitch_deg"] > base["rms_pitch_deg"] + 0.1


def _only(**spreads):
    return {name: Spread(0.0) for name in Tolerances.names()} | spreads


def test_a_unit_built_into_a_collision_is_reported_not_raised(design):
    tol = Tolerances(**_only(sensor_position_mm=Spread(5.0)))
    records = [evaluate_draw(Job(design, tol, FAST), draw_sample(tol, 2, 0, i)) for i in range(8)]
    invalid = [r for r in records if r["status"] == "invalid"]
    unfit = [r for r in records if r["status"] == "unfit"]
    assert invalid, "5 mm placement errors push some sensor into the sphere"
    assert all(not r["window_kept"] and math.isnan(r["rms_pitch_deg"]) for r in invalid)
    assert all(math.isnan(r["rms_pitch_deg"]) for r in unfit)
    assert not any(passes(r, parse_tolerance_config({}).targets) for r in invalid + unfit)


# --- Sobol indices ------------------------------------------------------------------------------


def _ishigami(x, a=7.0, b=0.1):
    return np.sin(x[:, 0]) + a * np.sin(x[:, 1]) ** 2 + b * x[:, 2] ** 4 * np.sin(x[:, 0])


def _pick_and_freeze(f, n, d, seed):
    """Outputs of f on A, B (uniform on [−π, π]^d) and every AB_i."""
    rng = np.random.default_rng(seed)
    A, B = rng.uniform(-np.pi, np.pi, (2, n, d))
    y_ab = []
    for i in range(d):
        ab = A.copy()
        ab[:, i] = B[:, i]
        y_ab.append(f(ab))
    return f(A), f(B), np.array(y_ab)


def _within(value, interval):
    return interval[0] <= value <= interval[1]


def test_sobol_indices_of_the_ishigami_function():
    """Analytic indices (a = 7, b = 0.1; Sobol' & Levitan 1999): V = a²/8 + bπ⁴/5 + b²π⁸/18 + ½,
    S1 = (½(1 + bπ⁴/5)²)/V, S2 = (a²/8)/V, S3 = 0, ST3 = (8b²π⁸/225)/V. Each lies inside
    its 99 % interval, every interval reaches into [0, 1], and none is flagged."""
    a, b = 7.0, 0.1
    v = a**2 / 8 + b * np.pi**4 / 5 + b**2 * np.pi**8 / 18 + 0.5
    v1, v2, v13 = 0.5 * (1 + b * np.pi**4 / 5) ** 2, a**2 / 8, 8 * b**2 * np.pi**8 / 225
    first = [v1 / v, v2 / v, 0.0]
    total = [(v1 + v13) / v, v2 / v, v13 / v]
    est = sobol_indices(*_pick_and_freeze(_ishigami, 4096, 3, seed=2), confidence=0.99)
    assert (est["rows"], est["dropped"], est["unused"], est["warnings"]) == (4096, 0, 0, [])
    assert est["variance"] == pytest.approx(v, rel=0.05)
    for key, exact in (("first", first), ("total", total)):
        for i in range(3):
            ci = est[f"{key}_ci"][i]
            assert ci[0] <= est[key][i] <= ci[1]
            assert _within(exact[i], ci), (key, i, exact[i], ci)
            assert ci[0] <= 1 and ci[1] >= 0 and not outside_unit_interval(ci)
            assert ci[1] - ci[0] < 0.12  # 4096 rows pin every index down to about ±0.05
    # the ranking the intervals support: x2 and x1 before x3 in first order; x1 first in total
    assert est["first_ci"][2][1] < min(est["first_ci"][0][0], est["first_ci"][1][0])
    assert est["total_ci"][0][0] > est["total_ci"][1][1] > est["total_ci"][2][1]


def test_sobol_indices_of_a_linear_model_with_an_idle_group():
    """y = 3 x1 + 2 x2 + x3 + 0 · x4 (independent, equal spreads): S_i = ST_i = a_i² / Σ a_j²
    = 9/14, 4/14, 1/14, and exactly 0 for x4 (its AB rows equal A's). Over 20 independent
    samples the 95 % intervals cover the analytic values at about their nominal rate (any one
    of them misses one time in twenty, so a single draw cannot show it)."""
    coefficients = np.array([3.0, 2.0, 1.0, 0.0])
    exact = coefficients**2 / np.sum(coefficients**2)
    covered, checks = 0, 0
    for draw in range(20):
        outputs = _pick_and_freeze(lambda x: x @ coefficients, 256, 4, seed=100 + draw)
        est = sobol_indices(*outputs, n_resamples=499, seed=draw)
        for key in ("first", "total"):
            ci = est[f"{key}_ci"]
            covered += sum(_within(exact[i], ci[i]) for i in range(3))
            checks += 3
            assert est[key][3] == 0.0 and list(ci[3]) == [0.0, 0.0]
            assert np.all(ci[:3, 0] <= 1) and np.all(ci[:3, 1] >= 0)  # reach into [0, 1]
    assert covered / checks >= 0.85, covered / checks
    # one group alone (scipy's squeezed result) carries all the variance
    alone = sobol_indices(outputs[0], outputs[1], outputs[1][None, :])
    assert _within(1.0, alone["total_ci"][0]) and _within(1.0, alone["first_ci"][0])


def test_sobol_rows_failed_units_and_the_seed():
    y_a, y_b, y_ab = _pick_and_freeze(_ishigami, 64, 3, seed=1)
    y_a[[3, 10]] = np.nan  # two units that could not be built
    y_ab[1, 20] = np.inf
    state = np.random.get_state()  # noqa: NPY002 (the global state must be left as it was)
    est = sobol_indices(y_a, y_b, y_ab, seed=4)
    assert np.array_equal(np.random.get_state()[1], state[1])  # noqa: NPY002
    assert (est["rows"], est["dropped"], est["unused"]) == (32, 3, 29)
    again = sobol_indices(y_a, y_b, y_ab, seed=4)
    other = sobol_indices(y_a, y_b, y_ab, seed=5)
    assert np.array_equal(est["total_ci"], again["total_ci"])
    assert np.array_equal(est["total"], other["total"])  # the estimate has no randomness
    assert not np.array_equal(est["total_ci"], other["total_ci"])
    with pytest.raises(InputError, match="fewer than two rows"):
        sobol_indices(np.full(4, np.nan), y_b[:4], y_ab[:, :4])
    with pytest.raises(InputError, match="shape"):
        sobol_indices(y_a, y_b, y_ab[:, :10])
    flat = sobol_indices(np.ones(8), np.ones(8), np.ones((2, 8)))  # no variance: undefined
    assert np.isnan(flat["total"]).all() and np.isnan(flat["first_ci"]).all()


def test_an_index_outside_the_unit_interval_is_flagged_only_beyond_its_interval():
    assert not outside_unit_interval((0.9, 1.3))  # 1.11 with this interval: scatter
    assert not outside_unit_interval((-0.004, -0.001))  # within the slack of 0
    assert outside_unit_interval((1.05, 1.2)) and outside_unit_interval((-0.2, -0.05))
    assert not outside_unit_interval((np.nan, np.nan))
    summary = sobol_summary(["x1", "x2"], *_fake_outputs())
    assert summary["outside"] == [
        {
            "tolerance": "x1",
            "index": "total",
            "value": summary["groups"][0]["total"],
            "ci": summary["groups"][0]["total_ci"],
        }
    ]


def _fake_outputs():
    """Outputs from a broken model run: AB_1 is A's output plus an unrelated constant-variance
    term, so its 'total index' is far above 1."""
    rng = np.random.default_rng(0)
    y_a, y_b = rng.normal(size=(2, 256))
    return y_a, y_b, np.array([y_a + 3.0 * rng.normal(size=256), y_a])


@pytest.mark.parametrize("rows", [1, 3, 100])
def test_sobol_rows_must_be_a_power_of_two(rows):
    with pytest.raises(InputError, match="power of two"):
        check_rows(rows)
    with pytest.raises(InputError, match=r"run\.sobol_samples: must be 0 \(off\) or a power"):
        parse_tolerance_config({"run": {"sobol_samples": rows}})
    assert [check_rows(n) for n in (0, 2, 256)] == [0, 2, 256]


def test_mix_takes_one_group_from_b():
    a, b = (draw_sample(Tolerances(), 2, 0, i) for i in (0, 1))
    row = mix(a, b, "gain", 9)
    assert row.index == 9 and row.noise_seed == a.noise_seed
    assert np.array_equal(row.standard["gain"], b.standard["gain"])
    assert np.array_equal(row.standard["offset_v"], a.standard["offset_v"])
    assert mix(a, b, NOISE, 9).noise_seed == b.noise_seed
    with pytest.raises(InputError, match="unknown tolerance"):
        mix(a, b, "colour", 9)


# --- the command line ---------------------------------------------------------------------------

SMALL = """
[settings]
calibration_step_deg = 2.0
n_validation = 300
metrics_step_deg = 2.0
[run]
samples = 6
oat_samples = 2
sobol_samples = 2
batch_size = 4
[tolerances]
multiplexed = true
"""


def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


@pytest.fixture
def design_file(tmp_path, design):
    path = tmp_path / "design.json"
    design.save(path)
    return str(path)


def test_cli_writes_samples_summary_and_figures(tmp_path, design_file, capsys):
    out = tmp_path / "out"
    config = _write(tmp_path, "tol.toml", SMALL)
    assert (
        main(["tolerance", design_file, "--tolerances", config, "--out", str(out), "--quiet"]) == 0
    )
    with open(out / "samples.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [int(r["index"]) for r in rows] == list(range(6))
    assert {r["S1_crosstalk_fraction"] for r in rows} == {"0.0"}  # multiplexed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["samples"] == 6 and 0 <= summary["yield"]["all"] <= 1
    assert summary["tolerances"]["multiplexed"] is True
    assert summary["settings"]["calibrate"] is True
    low, high = summary["yield_interval"]["all"]
    assert low <= summary["yield"]["all"] <= high
    assert (low, high) == pytest.approx(
        yield_interval(round(6 * summary["yield"]["all"]), 6), abs=1e-12
    )
    assert [g["tolerance"] for g in summary["sobol"]["groups"]][-1] == "noise"
    assert summary["one_at_a_time"][0]["tolerance"] == "none"
    for name in ("errors.png", "yield.png", "sensitivity.png"):
        assert (out / name).read_bytes()[:4] == b"\x89PNG"
    text = capsys.readouterr().out
    assert "6 units (seed 0" in text and "Sobol indices of the worse RMS error" in text
    assert "total index" in text and "first-order index" in text


def test_cli_geometry_only_study(tmp_path, design_file, capsys):
    out = tmp_path / "out"
    geometry = SMALL.replace("metrics_step_deg = 2.0", "metrics_step_deg = 2.0\ncalibrate = false")
    refused = _write(tmp_path, "tol.toml", geometry)  # sensitivity runs need the calibration
    assert main(["tolerance", design_file, "--tolerances", refused, "--out", str(out)]) == 2
    assert "set run.oat_samples and run.sobol_samples to 0" in capsys.readouterr().err
    assert not out.exists()
    config = _write(
        tmp_path, "geo.toml", geometry.replace("= 2\nsobol_samples = 2", "= 0\nsobol_samples = 0")
    )
    assert (
        main(["tolerance", design_file, "--tolerances", config, "--out", str(out), "--quiet"]) == 0
    )
    summary = json.loads((out / "summary.json").read_text())
    assert summary["settings"]["calibrate"] is False
    assert summary["yield"]["rms"] is None and summary["yield"]["all"] == summary["yield"]["window"]
    assert (out / "yield.png").is_file() and not (out / "errors.png").exists()
    assert "RMS ≤ 1° not assessed" in capsys.readouterr().out


@pytest.mark.parametrize(
    "extra, config, message",
    [
        (["--samples", "0"], SMALL, "argument --samples: expected a whole number from 1"),
        ([], SMALL + "\n[targets]\nrms_deg = 1\nmax = 2\n", "unknown key(s) max"),
        ([], SMALL.replace("multiplexed = true", "gain = -0.02"), "gain: expected a number from 0"),
        (["--seed", "-1"], SMALL, "argument --seed: expected a whole number ≥ 0"),
        ([], SMALL.replace("samples = 6", "samples = 6\nseed = -1"), "run.seed"),
    ],
)
def test_cli_bad_input_exits_2_and_writes_nothing(
    tmp_path, design_file, capsys, extra, config, message
):
    out = tmp_path / "out"
    path = _write(tmp_path, "tol.toml", config)
    argv = ["tolerance", design_file, "--tolerances", path, "--out", str(out), "--quiet", *extra]
    try:
        code = main(argv)
    except SystemExit as exc:  # a usage error, refused by argparse
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_cli_unreachable_scheduler_fails_fast(tmp_path, design_file, capsys):
    out = tmp_path / "out"
    config = _write(tmp_path, "tol.toml", SMALL)
    start = time.monotonic()
    argv = ["tolerance", design_file, "--tolerances", config, "--out", str(out), "--quiet"]
    assert main([*argv, "--scheduler", "tcp://127.0.0.1:1"]) == 2
    assert time.monotonic() - start < 30  # a hang guard, not a speed figure
    err = capsys.readouterr().err
    assert "cannot reach the Dask scheduler at tcp://127.0.0.1:1" in err
    assert len(err.strip().splitlines()) == 1
    assert not out.exists()


# --- sweeps -------------------------------------------------------------------------------------


def test_parse_variable_and_set_value(design):
    assert parse_variable("reflector.radius_mm=8.5:9.5:3") == (
        "reflector.radius_mm",
        [8.5, 9.0, 9.5],
    )
    assert parse_variable("sensors[1].axis[0]=0.1,-0.2") == ("sensors[1].axis[0]", [0.1, -0.2])
    doc = set_value(design.to_dict(), "sensors[1].position_mm[1]", 9.5)
    assert doc["sensors"][1]["position_mm"] == [0.0, 9.5, 0.0]
    assert design.sensors[1].position_mm == (0.0, 10.0, 0.0)  # the original is untouched
    for spec, message in (
        ("reflector.radius_mm", "expected PATH="),
        ("reflector.radius_mm=1:2", "START:STOP:N"),
        ("reflector.radius_mm=1,x", "START:STOP:N"),
        ("reflector.radius_mm=1,inf", "finite"),
        ("reflector..radius_mm=1", "path like"),
    ):
        with pytest.raises(InputError, match=re.escape(message)):
            parse_variable(spec)
    for path in ("reflector.radius", "sensors[5].axis[0]", "sensors[0].model"):
        with pytest.raises(InputError, match=re.escape(path)):
            set_value(design.to_dict(), path, 1.0)


def test_a_whole_number_of_the_design_is_swept_as_one(design):
    """--vary mechanics.n_units=2,4 marked every point invalid: 'expected a whole number
    from 1 to 1000, got 2.0'."""
    doc = set_value(design.to_dict(), "mechanics.n_units", 2.0)
    assert doc["mechanics"]["n_units"] == 2 and isinstance(doc["mechanics"]["n_units"], int)
    assert Design.from_dict(doc).mechanics.n_units == 2
    doc = set_value(design.to_dict(), "mechanics.n_units", 2.5)  # refused by the design
    with pytest.raises(InputError, match=r"mechanics\.n_units: must be a whole number"):
        Design.from_dict(doc)
    radius = set_value(design.to_dict(), "reflector.radius_mm", 9.0)["reflector"]["radius_mm"]
    assert isinstance(radius, float)  # a float of the design stays a float


def test_sweep_reports_each_point_and_invalid_ones(design):
    variables = [("reflector.radius_mm", [9.0, 8.5]), ("sensors[0].position_mm[0]", [10.0, 5.0])]
    with ThreadPoolExecutor(2) as pool:
        rows = sweep(design, variables, samples=2, seed=1, settings=FAST, factory=supplied(pool))
    assert [(r["reflector.radius_mm"], r["sensors[0].position_mm[0]"]) for r in rows] == [
        (9.0, 10.0),
        (9.0, 5.0),
        (8.5, 10.0),
        (8.5, 5.0),
    ]
    assert rows[1]["status"].startswith("invalid: sensors: S1")  # 5 mm from O: inside the sphere
    assert math.isnan(rows[1]["nominal_rms_pitch_deg"])
    nominal = evaluate_draw(
        Job(design, Tolerances.zero(), FAST), draw_sample(Tolerances(), 2, 1, 0)
    )
    assert rows[0]["nominal_rms_pitch_deg"] == nominal["rms_pitch_deg"]
    assert 0 <= rows[0]["yield"] <= 1


def test_cli_sweep_bad_path_exits_2(tmp_path, design_file, capsys):
    out = tmp_path / "sweep"
    argv = ["sweep", design_file, "--vary", "reflector.radius=9", "--out", str(out), "--quiet"]
    assert main(argv) == 2
    assert "the design has no 'radius'" in capsys.readouterr().err
    assert not out.exists()


def _record(status, window, margin, rms, worst):
    nan = math.nan
    return {
        "status": status,
        "window_kept": window,
        "distance_margin_mm": margin if status == "ok" else nan,
        "resolution_pitch_deg": 0.1,
        "resolution_roll_deg": 0.1,
        "wall_min_mm": 1.0,
        "rms_pitch_deg": rms,
        "rms_roll_deg": rms / 2,
        "max_pitch_deg": worst,
        "max_roll_deg": worst / 2,
    }


def test_summary_yield_and_required_margin_hand_values():
    records = [
        _record("ok", True, 0.20, 0.5, 2.0),  # passes
        _record("ok", True, 0.10, 1.5, 2.0),  # RMS too large
        _record("ok", False, -0.05, 0.5, 4.0),  # window lost, maximum too large
        _record("invalid", False, math.nan, math.nan, math.nan),
    ]
    s = summarise(records, Targets(rms_deg=1.0, max_deg=3.0), coverage=1.0, nominal_margin_mm=0.3)
    assert s["yield"] == {"all": 0.25, "window": 0.5, "rms": 0.5, "max": 0.5}
    assert (s["samples"], s["invalid"], s["unfit"]) == (4, 1, 0)
    assert s["required_margin_mm"]["value"] == pytest.approx(0.35)  # 0.3 − (−0.05)
    assert s["distributions"]["distance_margin_mm"]["max"] == pytest.approx(0.2)


def test_required_margin_is_a_confidence_bound_with_enough_units():
    """300 units ≥ 299: the 95 % bound on the 99 % quantile of the loss is the largest loss."""
    losses = np.linspace(0.0, 0.299, 300)
    records = [_record("ok", True, 0.3 - loss, 0.5, 2.0) for loss in losses]
    s = summarise(records, Targets(rms_deg=1.0, max_deg=3.0), nominal_margin_mm=0.3)
    required = s["required_margin_mm"]
    assert required["confidence"] == 0.95
    assert required["value"] == pytest.approx(0.299)
    assert required["estimate"] == pytest.approx(np.quantile(losses, 0.99))


def test_example_config_reads_as_documented():
    from pathlib import Path

    from reflector_opt.tolerance.config import load_tolerance_config

    path = Path(__file__).resolve().parents[2] / "examples" / "tolerance.toml"
    config = load_tolerance_config(path)
    assert config.tolerances.sensor_tilt_deg == Spread(2.0, "uniform")
    assert config.tolerances.centre_offset_mm == Spread(0.05, "normal")
    assert config.tolerances.crosstalk_fraction == Spread(0.01, "uniform")
    assert config.settings == Settings()
    assert config.targets == Targets()
    assert (config.run.samples, config.run.sobol_samples) == (500, 256)


# --- the tolerance study without calibration --------------------------------------------------


def test_geometry_only_records_match_the_calibrated_ones(design):
    tol = Tolerances(sensor_position_mm=Spread(0.3))  # large: some units lose the window
    with ThreadPoolExecutor(1) as pool:
        full = run_study(design, tol, samples=12, seed=2, settings=FAST, factory=supplied(pool))
        geometry = run_study(
            design,
            tol,
            samples=12,
            seed=2,
            settings=dataclasses.replace(FAST, calibrate=False),
            factory=supplied(pool),
        )
    for a, b in zip(full.records, geometry.records, strict=True):
        assert b["status"] == ("uncalibrated" if a["status"] != "invalid" else "invalid")
        for key in ("window_kept", "distance_margin_mm", "resolution_pitch_deg", "wall_min_mm"):
            assert a[key] == b[key] or (math.isnan(a[key]) and math.isnan(b[key]))
        assert math.isnan(b["rms_pitch_deg"]) and math.isnan(b["max_roll_deg"])
    s = geometry.summary
    kept = sum(r["window_kept"] for r in full.records)
    assert 0 < kept < 12
    assert s["yield"] == {"all": kept / 12, "window": kept / 12, "rms": None, "max": None}
    assert s["required_margin_mm"] == full.summary["required_margin_mm"]


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"oat_samples": 4}, "set run.oat_samples and run.sobol_samples to 0"),
        ({"targets": Targets(window=False)}, "targets.window must be true"),
        ({"coverage": 1.0}, "coverage: must be strictly between 0 and 1"),
        ({"coverage": 0}, "coverage: must be strictly between 0 and 1"),
    ],
)
def test_study_refuses_what_it_cannot_judge(design, kwargs, message):
    settings = dataclasses.replace(FAST, calibrate=False)
    with pytest.raises(InputError, match=message):
        run_study(design, samples=2, settings=settings, **kwargs)


# --- yield intervals ------------------------------------------------------------------------------


def _wilson(k, n, confidence=0.95):
    """Wilson (1927) score interval, written out."""
    z = norm.ppf(0.5 + confidence / 2)
    p = k / n
    centre = (p + z**2 / (2 * n)) / (1 + z**2 / n)
    half = z / (1 + z**2 / n) * math.sqrt(p * (1 - p) / n + z**2 / (4 * n**2))
    return centre - half, centre + half


def test_quantile_upper_bound_by_hand():
    """0.99²⁹⁹ = 0.0495 < 5 %: with 299 samples the maximum bounds the 99 % quantile at 95 %;
    0.99²⁹⁸ = 0.0500 > 5 %: 298 samples cannot."""
    assert quantile_upper_bound(np.arange(299.0), 0.99) == 298.0
    assert quantile_upper_bound(np.arange(298.0), 0.99) is None
    # median at 95 %: the smallest k with P(Bin(20, 1/2) ≤ k − 1) ≥ 0.95 is k = 15
    assert quantile_upper_bound(np.arange(1.0, 21.0), 0.5) == 15.0


def test_quantile_upper_bound_covers_the_true_quantile_95_percent_of_the_time():
    """Monte Carlo: 4,000 sets of 500 normal samples. The bound is the 499th of 500, above
    the true 99 % quantile with probability P(Bin(500, 0.99) ≤ 498) = 96.02 % (≥ 95 %, the
    excess from k being whole); the fraction of sets has σ 0.31 %."""
    rng = np.random.default_rng(3)
    true_quantile = norm.ppf(0.99)
    covered = [
        quantile_upper_bound(rng.standard_normal(500), 0.99) >= true_quantile for _ in range(4000)
    ]
    assert np.mean(covered) == pytest.approx(0.9602, abs=0.0125)  # 4 σ


@pytest.mark.parametrize(("passed", "samples"), [(45, 50), (20, 20), (0, 7), (1, 3)])
def test_yield_interval_is_wilsons_and_contains_the_estimate(passed, samples):
    low, high = yield_interval(passed, samples)
    assert (low, high) == pytest.approx(_wilson(passed, samples), abs=1e-12)
    assert 0.0 <= low <= passed / samples <= high <= 1.0
    assert low < high


def test_yield_interval_by_hand():
    # 45 of 50, z = 1.959964, z² = 3.841459: centre (0.9 + 0.038415) / 1.076829 = 0.871461,
    # half (1.959964 / 1.076829) · sqrt(0.0018 + 0.000384146) = 1.820125 · 0.046735 = 0.085063
    assert yield_interval(45, 50) == pytest.approx((0.786398, 0.956524), abs=2e-6)
    # all of 20 pass: the interval still has width, [20 / (20 + z²), 1]
    assert yield_interval(20, 20) == pytest.approx((20 / (20 + 1.959964**2), 1.0), abs=1e-6)


# --- fewer runs for the same results ----------------------------------------------------------


def test_a_sensitivity_record_holds_the_full_records_calibrated_errors(design):
    """``Job(full=False)`` skips the geometry and the misfit fit, not the calibrated error."""
    tol = Tolerances(sensor_position_mm=Spread(0.3))  # some units invalid or window lost
    full, short = Job(design, tol, FAST), Job(design, tol, FAST, full=False)
    for i in range(6):
        draw = draw_sample(tol, 2, 3, i)
        a, b = evaluate_draw(full, draw), evaluate_draw(short, draw)
        assert a["status"] == b["status"]
        for key in ("rms_pitch_deg", "rms_roll_deg", "max_pitch_deg", "max_roll_deg"):
            assert a[key] == b[key] or (math.isnan(a[key]) and math.isnan(b[key]))
        for key in ("distance_margin_mm", "resolution_roll_deg", "misfit_rms_deg"):
            assert math.isnan(b[key])


def test_sobol_rows_taken_from_the_sample_give_the_indices_of_rows_run_apart(design):
    """With 8 samples the Sobol matrices A and B (4 rows each) are the sample's own records;
    with 2 samples six of their rows are run apart. The indices must not tell the difference,
    nor the one-at-a-time runs, which reuse the sample's first draws likewise."""
    with ThreadPoolExecutor(1) as pool:
        runs = [
            run_study(
                design,
                samples=samples,
                seed=4,
                settings=FAST,
                oat_samples=3,
                sobol_samples=4,
                factory=supplied(pool),
            )
            for samples in (8, 2)
        ]
    assert runs[0].sobol == runs[1].sobol and runs[0].sobol["rows"] > 0
    assert runs[0].one_at_a_time == runs[1].one_at_a_time
    assert runs[0].records[:2] == runs[1].records


def test_units_of_one_optics_share_their_voltages_and_keep_their_records(design):
    """A Sobol row's AB rows for the read-out tolerances, the inner radius and the noise have
    the optics of their row of A: a batch computes their forward voltages once. Each record
    must equal the one evaluated alone, and the geometric groups' rows must not share."""
    tol = Tolerances()
    a, b = draw_sample(tol, 2, 5, 0), draw_sample(tol, 2, 5, 1)
    rows = [mix(a, b, group, 10 + g) for g, group in enumerate((*tol.active(), NOISE))]
    job = Job(design, tol, FAST, full=False)
    batch = evaluate_draws(job, rows)
    alone = [evaluate_draw(job, row) for row in rows]
    assert batch == alone and all(r["status"] == "ok" for r in batch)
    outputs = {g: r["rms_pitch_deg"] for g, r in zip((*tol.active(), NOISE), batch, strict=True)}
    assert outputs["sensor_tilt_deg"] != outputs["gain"]  # different optics, different data
