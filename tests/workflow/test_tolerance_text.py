"""The tolerance study's and the sweep's text say what their yield is computed on.

One quantity, one number, or its basis said (issue 37, item 4): the yield was 88.9 % from
tolerance and 94 % from sweep (other files, sample sizes, targets), neither saying which.
"""

from types import SimpleNamespace

from reflector_opt.workflow._tolerance_text import format_summary, format_table, yield_basis

DIST = {"median": 0.1, "p95": 0.2, "max": 0.3}


def _study():
    summary = {
        "samples": 500,
        "invalid": 0,
        "unfit": 0,
        "yield": {"all": 0.889, "window": 0.95, "rms": 0.9, "max": 0.92},
        "yield_interval": {"all": (0.86, 0.91)},
        "targets": {"rms_deg": 0.5, "max_deg": 2.0},
        "distributions": {
            k: DIST
            for k in (
                "rms_pitch_deg",
                "rms_roll_deg",
                "max_pitch_deg",
                "max_roll_deg",
                "distance_margin_mm",
            )
        },
    }
    return SimpleNamespace(summary=summary, seed=3, sobol=None)


def test_tolerance_names_its_units_seed_and_file():
    first = format_summary(_study(), "examples/tolerance.toml").splitlines()[0]
    assert first.startswith("500 units (seed 3, tolerances examples/tolerance.toml; ")
    assert "yield 88.9 %" in first
    assert "tolerances built-in;" in format_summary(_study()).splitlines()[0]


def test_sweep_names_what_its_yield_counts():
    row = {
        "reflector.radius_mm": 8.4,
        "status": "ok",
        "nominal_resolution_pitch_deg": 0.02,
        "nominal_resolution_roll_deg": 0.02,
        "nominal_window_kept": True,
        "nominal_distance_margin_mm": 0.1,
        "nominal_rms_pitch_deg": 0.2,
        "nominal_rms_roll_deg": 0.2,
        "yield": 0.94,
    }
    basis = yield_basis(50, 0, None)
    line = format_table([row], ["reflector.radius_mm"], basis)
    assert line.endswith("yield 94.0 % (50 units, seed 0, tolerances built-in, all targets)")
