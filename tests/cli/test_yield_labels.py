"""One quantity, one number, or its basis said (issue 37, item 4).

The --sensor auto ranking printed a calibration RMS of 0.072/0.075° and the prediction
below it 0.081/0.085° (one built unit against four); the yield was 88.9 % from tolerance,
80.4 % from optimise --tolerances and 94 % from sweep (other files, sample sizes, targets),
none saying which. Each now names what it is computed on.
"""

from types import SimpleNamespace

from reflector_opt.cli.optimise import format_pareto, format_robust, ranking_basis
from reflector_opt.workflow.tolerance_text import format_summary, format_table, yield_basis

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


def test_the_sensor_ranking_says_its_calibration_rms_is_on_one_unit_not_four():
    choice = {"calibration": "recommended calibration of 1 built unit (…)", "seed": 0}
    calibration = {"protocol": {"n_units": 4, "seed": 0}}
    (line,) = ranking_basis(choice, calibration)
    assert "ranking's calibration RMS: recommended calibration of 1 built unit" in line
    assert "the predicted calibration below: 4 built units, seed 0" in line


def test_optimise_names_the_yields_basis_and_file():
    point = SimpleNamespace(
        required_margin_mm=0.1,
        feasible=True,
        margin_mm=0.12,
        worst_pitch_deg=0.02,
        worst_roll_deg=0.02,
        yield_fraction=0.804,
        yield_low=0.7,
        yield_high=0.9,
    )
    basis = {"calibrated": True, "samples": 200, "seed": 0}
    front = SimpleNamespace(points=[point], seed=0, yield_basis=basis)
    header = format_pareto(front, "examples/tolerance.toml").splitlines()[1]
    assert "yield (200 units, seed 0, tolerances examples/tolerance.toml, all targets)" in header
    run = SimpleNamespace(samples=200, seed=0)
    robust = SimpleNamespace(
        options=SimpleNamespace(coverage=0.99),
        converged=True,
        tolerance=SimpleNamespace(run=run),
        rounds=[
            {
                "round": 1,
                "limit_mm": 0.1,
                "margin_mm": 0.1,
                "required_mm": 0.1,
                "window_yield": 0.99,
                "window_yield_interval": (0.98, 1.0),
                "objective_deg": 0.02,
                "required_confidence": 0.95,
            }
        ],
    )
    first = format_robust(robust, "examples/tolerance.toml").splitlines()[0]
    assert "seed 0, tolerances examples/tolerance.toml; its yield counts the distance window" in (
        first
    )
