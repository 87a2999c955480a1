"""Tolerance model, as-built unit, per-sample analysis, the study, sweeps and the CLI."""

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
    supplied,
)
from reflector_opt.tolerance.analysis import evaluate_draws, passes, read_out
from reflector_opt.tolerance.config import parse_tolerance_config
from reflector_opt.tolerance.sensitivity import NOISE, mix
from reflector_opt.tolerance.statistics import yield_interval
from reflector_opt.tolerance.study import run_study
from reflector_opt.tolerance.sweep import parse_variable, set_value, sweep
from reflector_opt.tolerance.tolerances import Electrical
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
