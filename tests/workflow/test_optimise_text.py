"""optimise's text: what the ranking's calibration RMS is computed on, the yields' basis and
tolerance file, and a run's text naming the file its tolerances came from."""

from pathlib import Path
from types import SimpleNamespace

from reflector_opt.design import load_design
from reflector_opt.workflow import OptimiseRun
from reflector_opt.workflow._optimise_text import (
    format_pareto,
    format_robust,
    ranking_basis,
    resolution_text,
)

SAMPLE = (
    Path(__file__).resolve().parents[2] / "tests" / "data" / "design_6c47a9f.json"
)  # white noise


def test_the_sensor_ranking_says_its_calibration_rms_is_on_one_unit_not_four():
    choice = {"calibration": "recommended calibration of 1 built unit (…)", "seed": 0}
    calibration = {"protocol": {"n_units": 4, "seed": 0}}
    (line,) = ranking_basis(choice, calibration)
    assert "ranking's calibration RMS: recommended calibration of 1 built unit" in line
    assert "the predicted calibration below: 4 built units, seed 0" in line


def _front():
    """A Pareto front of one point with its yield, as the optimiser returns it."""
    point = SimpleNamespace(
        required_margin_mm=0.1,
        feasible=True,
        margin_mm=0.12,
        worst_pitch_deg=0.02,
        worst_roll_deg=0.02,
        worst_case_deg=float("nan"),  # traced without conditions
        yield_fraction=0.804,
        yield_low=0.7,
        yield_high=0.9,
    )
    basis = {"calibrated": True, "samples": 200, "seed": 0}
    return SimpleNamespace(points=[point], seed=0, yield_basis=basis)


def _robust():
    """One covered robust round on 200 units, as the optimiser returns it."""
    return SimpleNamespace(
        options=SimpleNamespace(coverage=0.99),
        converged=True,
        tolerance=SimpleNamespace(run=SimpleNamespace(samples=200, seed=0)),
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


def test_optimise_names_the_yields_basis_and_file():
    header = format_pareto(_front(), "examples/tolerance.toml").splitlines()[1]
    assert "yield (200 units, seed 0, tolerances examples/tolerance.toml, all targets)" in header
    first = format_robust(_robust(), "examples/tolerance.toml").splitlines()[0]
    assert "seed 0, tolerances examples/tolerance.toml; its yield counts the distance window" in (
        first
    )
    # 0.99 of 0.98-1.0: the round's row gives the yield and its interval in percent
    assert "99.0 % [98.0–100.0 %]" in format_robust(_robust()).splitlines()[2]


def test_a_runs_text_is_its_design_and_names_the_runs_tolerance_file():
    """The run carries what the command line gave (the tolerance file); its text stops before
    the files written, which the command prints."""
    design = load_design(SAMPLE)
    result = SimpleNamespace(design=design, seed=3, evaluations={"search": 100, "polish": 20})
    run = OptimiseRun(result, _robust(), _front(), None, None, Path("out"), [], "tol.toml")
    lines = run.text().splitlines()
    assert lines[0] == "optimised design (seed 3, 120 model evaluations)"
    assert lines[1].startswith(f"  reflector: radius {design.reflector.radius_mm:.3f} mm, centre")
    assert sum("tolerances tol.toml" in line for line in lines) == 2  # the rounds, the front
    assert lines[-2:] == [
        "  required (mm)  margin (mm)  pitch (°)  roll (°)  yield (200 units, "
        "seed 0, tolerances tol.toml, all targets) [95 % interval]",
        "          0.100        0.120     0.0200    0.0200  80.4 % [70.0–90.0 %]",
    ]
    built_in = OptimiseRun(result, _robust(), None, None, None, Path("out"), [])
    assert "tolerances built-in; its yield" in built_in.text()
    assert repr(built_in) == built_in.text()


def test_a_resolution_is_four_decimals_or_inf():
    assert resolution_text(0.088549) == "0.0885°"
    assert resolution_text(None) == "inf"
