"""The tolerance study: its command line, the study without calibration, fewer runs."""

import csv
import dataclasses
import json
import math
import time
from concurrent.futures import ThreadPoolExecutor

import pytest

from reflector_opt.cli import main
from reflector_opt.tolerance import (
    Job,
    Spread,
    Targets,
    Tolerances,
    draw_sample,
    evaluate_draw,
)
from reflector_opt.tolerance._analysis import evaluate_draws
from reflector_opt.tolerance._sensitivity import NOISE, mix
from reflector_opt.tolerance._statistics import yield_interval
from reflector_opt.tolerance._study import run_study
from reflector_opt.util._errors import InputError
from reflector_opt.util._pools import supplied
from tests.tolerance.fast import FAST

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
        (["--samples", "0"], SMALL, "--samples: expected a whole number from 1"),
        ([], SMALL + "\n[targets]\nrms_deg = 1\nmax = 2\n", "unknown key(s) max"),
        ([], SMALL.replace("multiplexed = true", "gain = -0.02"), "gain: expected a number from 0"),
        (["--seed", "-1"], SMALL, "--seed: expected a whole number from 0"),
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


def test_cli_sweep_bad_path_exits_2(tmp_path, design_file, capsys):
    out = tmp_path / "sweep"
    argv = ["sweep", design_file, "--vary", "reflector.radius=9", "--out", str(out), "--quiet"]
    assert main(argv) == 2
    assert "the design has no 'radius'" in capsys.readouterr().err
    assert not out.exists()


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


@pytest.mark.parametrize(
    ("samples", "oat", "sobol"), [(5, 0, 0), (5, 3, 0), (5, 0, 2), (3, 2, 4), (8, 8, 4)]
)
def test_planned_units_count_the_plan_before_any_draw(samples, oat, sobol):
    from reflector_opt.design import default_design
    from reflector_opt.tolerance import Tolerances
    from reflector_opt.tolerance._study import _StudyPlan, planned_units

    tolerances = Tolerances()
    active = len(tolerances.active())
    plan = _StudyPlan(default_design(), tolerances, FAST, samples, 0, oat, sobol)
    assert planned_units(tolerances, samples, oat, sobol) == plan.units()
    # by hand for (3, 2, 4): 3 + 1 nominal, 2 × (1 + active) one-at-a-time, 8 − 3 rows of A
    # and B beyond the sample, 4 × (active + 1) rows of AB
    if (samples, oat, sobol) == (3, 2, 4):
        assert plan.units() == 4 + 2 * (1 + active) + 5 + 4 * (active + 1)


def test_a_study_too_large_is_refused_before_its_draws(monkeypatch):
    from reflector_opt.design import default_design
    from reflector_opt.tolerance import _study as study

    def no_draws(*args, **kwargs):
        raise AssertionError("drew a sample before refusing the study")

    monkeypatch.setattr(study, "draw_sample", no_draws)
    with pytest.raises(InputError, match="simulated units, more than the limit"):
        run_study(default_design(), samples=100_000, sobol_samples=65_536)
