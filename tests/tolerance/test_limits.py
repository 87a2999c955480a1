"""Studies and sweeps too large for one run are refused before any work starts."""

import pytest

from reflector_opt.tolerance import Settings, Tolerances
from reflector_opt.tolerance._config import RunOptions, parse_tolerance_config
from reflector_opt.tolerance._study import run_study
from reflector_opt.tolerance._sweep import parse_variable, sweep
from reflector_opt.util._errors import InputError


def _no_executor():
    raise AssertionError("the work started")


@pytest.mark.parametrize(
    ("document", "fragment"),
    [
        (
            {"settings": {"n_validation": 10**12}},
            "settings.n_validation: expected a whole number from 1 to 1000000, got 10",
        ),
        (
            {"run": {"samples": 10**12}},
            "run.samples: expected a whole number from 1 to 100000, got 10",
        ),
        ({"run": {"sobol_samples": 10**9}}, "run.sobol_samples"),
        (
            {"run": {"workers": 10**6}},
            "run.workers: expected a whole number from 1 to 256, got 1000000",
        ),
        ({"run": {"batch_size": 10**9}}, "run.batch_size"),
    ],
)
def test_config_sizes_have_limits(document, fragment):
    with pytest.raises(InputError) as exc:
        parse_tolerance_config(document)
    assert fragment in str(exc.value)


@pytest.mark.parametrize(
    ("options", "fragment"),
    [
        ({"settings": Settings(calibration_step_deg=1e-6)}, "settings.calibration_step_deg"),
        ({"settings": Settings(metrics_step_deg=1e-6)}, "settings.metrics_step_deg = 1e-06°"),
        (
            {"samples": 10_000, "settings": Settings(n_validation=1_000_000)},
            "model evaluations",
        ),
        ({"samples": 90_000, "oat_samples": 10_000}, "simulated units"),
    ],
)
def test_a_study_beyond_the_limits_is_refused_before_it_starts(design, options, fragment):
    with pytest.raises(InputError) as exc:
        run_study(design, Tolerances(), factory=_no_executor, **options)
    assert fragment in str(exc.value)


def test_sweep_sizes_are_checked_before_anything_is_allocated(design):
    with pytest.raises(InputError, match=r"asks for 1,000,000,000,000 values"):
        parse_variable("reflector.radius_mm=8:10:1000000000000")
    with pytest.raises(InputError, match=r"asks for 10,001 values"):
        parse_variable("noise.sigma_v=" + ",".join(["0.001"] * 10_001))
    variables = [parse_variable("reflector.radius_mm=8:10:200")] * 2
    with pytest.raises(InputError, match=r"asks for 40,000 points"):
        sweep(design, variables, factory=_no_executor)
    one = [parse_variable("reflector.radius_mm=8:10:10")]
    with pytest.raises(InputError, match=r"sweep points × \(1 \+ samples\)"):
        sweep(design, one, samples=50_000, factory=_no_executor)


def test_run_options_accept_the_defaults_and_the_limits():
    assert RunOptions(samples=100_000, workers=256).samples == 100_000


@pytest.mark.parametrize(
    ("variables", "message"),
    [
        (
            [("mechanics.n_units", [2.0, 2.5])],
            r"^--vary mechanics\.n_units=2\.5: mechanics\.n_units: "
            "expected a whole number from 1 to 1000",
        ),
        (
            [("noise.sigma_v", [0.002]), ("workspace.step_deg", [1e-7])],
            r"^--vary noise\.sigma_v=0\.002, workspace\.step_deg=1e-07: workspace\.step_deg = "
            r"1e-07°: asks for 9e\+16 grid poses",
        ),
        (
            [("sensors[0].axis[0]", [0.0])],
            r"^--vary sensors\[0\]\.axis\[0\]=0: sensor 'S1'\.axis: must not be the zero vector",
        ),
    ],
    ids=["fractional-units", "step", "zero-axis"],
)
def test_a_sweep_of_values_the_design_refuses_is_refused_before_it_starts(
    design, variables, message
):
    """Each such point was reported as an invalid row of a sweep that went on."""
    with pytest.raises(InputError, match=message):
        sweep(design, variables, factory=_no_executor)


def test_a_sweep_point_that_cannot_be_built_is_a_row_as_evaluate_judges_it(design):
    """A point whose parts evaluate refuses to lay out was reported 'ok', with its figures."""
    from concurrent.futures import ThreadPoolExecutor

    from reflector_opt.util._pools import supplied

    fast = Settings(calibration_step_deg=2.0, n_validation=300, metrics_step_deg=2.0)
    with ThreadPoolExecutor(2) as pool:
        rows = sweep(
            design,
            [("reflector.inner_radius_mm", [5.0, 7.5])],
            settings=fast,
            factory=supplied(pool),
        )
    assert rows[0]["status"].startswith("invalid: reflector.inner_radius_mm: 5 mm does not clear")
    assert rows[0]["nominal_rms_pitch_deg"] != rows[0]["nominal_rms_pitch_deg"]  # NaN
    assert rows[1]["status"] == "ok" and rows[1]["nominal_rms_pitch_deg"] > 0
