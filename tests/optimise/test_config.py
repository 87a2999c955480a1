"""The optimiser's TOML configuration: defaults, overrides and clear errors."""

import tomllib
from pathlib import Path

import pytest

from reflector_opt.optimiser import Problem, SearchBudget
from reflector_opt.optimiser._config import OptimiseConfig, load_config, parse_config
from reflector_opt.optimiser._robust import RobustOptions
from reflector_opt.util._errors import InputError

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "optimise.toml"


def test_empty_config_is_the_default():
    config = parse_config({})
    assert config == OptimiseConfig()
    assert config.problem == Problem()
    assert config.budget == SearchBudget()
    assert config.seed == 0


def test_example_file_restates_the_defaults():
    config = load_config(EXAMPLE)
    assert config.problem == Problem()
    assert config.budget == SearchBudget()
    assert config.robust == RobustOptions()
    assert config == OptimiseConfig()


def test_robust_section_sets_coverage_and_rounds():
    config = parse_config({"robust": {"coverage": 0.95, "max_rounds": 2}})
    assert config.robust == RobustOptions(coverage=0.95, max_rounds=2)


def test_overrides_reach_the_problem_and_budget():
    config = parse_config(
        tomllib.loads(
            """
            [sensor]
            range_mm = [0.6, 2.5]
            [workspace]
            pitch_deg = [-10, 12]
            [mechanics]
            unit_diameter_mm = 24
            [noise]
            sigma_v = 0.005
            [bounds]
            centre_z_mm = [-2, 0]
            sensor_azimuth_deg = [0, 90]
            [objective]
            isotropy_weight = 0.0
            [constraints]
            distance_margin_mm = 0.15
            [search]
            seed = 7
            popsize = 6
            workers = 1
            [pareto]
            margins_mm = [0.2, 0.0]
            [cad]
            clearance_mm = 0.3
            """
        )
    )
    p = config.problem
    assert p.sensor.range_mm == (0.6, 2.5) and p.sensor.name == "NJL5901R-2"
    assert p.workspace.pitch_deg == (-10.0, 12.0) and p.workspace.roll_deg == (-15.0, 15.0)
    assert p.mechanics.unit_diameter_mm == 24.0
    assert p.noise.sigma_v == 0.005
    assert p.bounds["centre_z_mm"] == (-2.0, 0.0)
    assert "sensor_azimuth_deg" in p.free_names
    assert p.bounds["gap_mm"] == (0.6, 2.5)  # the default follows the part's range
    assert p.bounds["sensor_radius_mm"][1] == 11.0  # and the envelope: 24/2 − 1 mm backing
    assert p.isotropy_weight == 0.0 and p.distance_margin_mm == 0.15
    assert config.seed == 7
    assert config.budget.popsize == 6 and config.budget.workers == 1
    assert config.pareto_margins_mm == (0.0, 0.2)
    assert p.cad.clearance_mm == 0.3 and p.cad.footprint_factor == 1.5


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("[sensors]\nmodel = 'x'", "unknown section(s) sensors"),
        ("[bounds]\nradius = [1, 2]", "bounds.radius: unknown design variable"),
        ("[bounds]\nradius_mm = [8, 9]", "bounds.radius_mm: not a search variable; the sphere"),
        ("[search]\npopsize = 8\nspeed = 2", "[search]: unknown key(s) speed"),
        ("[bounds]\ncentre_z_mm = [1, -1]", "centre_z_mm: min 1.0 is greater than max -1.0"),
        (
            "[bounds]\ncentre_z_mm = [1]",
            "bounds.centre_z_mm: expected a list of 2 numbers from -1000 to 1000 mm, got [1]",
        ),
        ("[sensor]\nrange_mm = [3, 1]", "sensor.range_mm: min 3.0 is greater than max 1.0"),
        # the key was missing: 'unknown sensor preset …'
        ("[sensor]\nmodel = 'TCRT5000'", "sensor.model: unknown sensor preset 'TCRT5000'"),
        # named the derived bounds.sensor_radius_mm, which the user had not set
        ("[constraints]\nsensor_backing_mm = 20", "sensor_backing_mm: 20.0 mm of room"),
        ("[sensor]\nrange_mm = [0, 3]", "the default, from the sensor's range_mm"),
        ("[workspace]\nroll_deg = [5, -5]", "workspace.roll_deg: min must be below max"),
        (
            "[mechanics]\nunit_diameter_mm = -3",
            "mechanics.unit_diameter_mm: expected a number > 0 and ≤ 1000 mm, got -3",
        ),
        (
            "[noise]\nadc_bits = 12.5",
            "noise.adc_bits: expected a whole number from 1 to 32, got 12.5",
        ),
        (
            "[objective]\nisotropy_weight = -1",
            "objective.isotropy_weight: expected a number from 0 to 1000000, got -1",
        ),
        ("[search]\npopsize = 0", "search.popsize: expected a whole number from 1 to 1000, got 0"),
        ("[search]\nseed = -1", "search.seed"),
        ("[pareto]\nmargins_mm = []", "pareto.margins_mm"),
        ("sensor = 3", "sensor: expected a table, got 3"),
        (
            "[cad]\nclearence_mm = 0.2",
            "[cad]: unknown key(s) clearence_mm; allowed: clearance_mm, footprint_factor",
        ),
        (
            "[cad]\nclearance_mm = -0.2",
            "cad.clearance_mm: expected a number from 0 to 1000 mm, got -0.2",
        ),
    ],
)
def test_bad_settings_name_the_key(text, fragment):
    with pytest.raises(InputError) as err:
        parse_config(tomllib.loads(text))
    assert fragment in str(err.value)


@pytest.mark.parametrize(
    ("text", "constraint"),
    [
        # a 0.2 mm usable range cannot hold a 0.1 mm margin at both ends
        ("[sensor]\nrange_mm = [0.5, 0.7]", "distance window"),
        # a longer-range part cannot sit close enough for a wall above the bearing
        ("[sensor]\nmodel = 'QRE1113'", "wall"),
        # sensors forced outside the 22 mm unit
        ("[bounds]\nsensor_radius_mm = [10.5, 11]", "sensor envelope"),
    ],
)
def test_infeasible_settings_say_which_constraint(text, constraint):
    with pytest.raises(InputError) as err:
        parse_config(tomllib.loads(text))
    assert str(err.value).startswith(constraint)


def test_load_config_errors_name_the_file(tmp_path):
    with pytest.raises(InputError, match="cannot read"):
        load_config(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[search\nseed = 1\n")
    with pytest.raises(InputError, match=r"bad\.toml: not valid TOML"):
        load_config(bad)
    unknown = tmp_path / "unknown.toml"
    unknown.write_text("[objective]\nweight = 1\n")
    with pytest.raises(InputError, match=r"unknown\.toml: \[objective\]: unknown key"):
        load_config(unknown)


def test_surface_section_sets_the_material_and_the_interval():
    config = parse_config({"surface": {"material": "matte"}})
    assert config.problem.surface.specular_fraction == 0.0
    assert config.problem.specular_fractions == (0.0,)
    config = parse_config(
        {"surface": {"specular_fraction": 0.2, "specular_fraction_range": [0.0, 0.4]}}
    )
    assert config.problem.surface.specular_fraction == 0.2
    assert config.problem.surface.reflectance == 0.9
    assert config.problem.specular_fractions == (0.0, 0.2, 0.4)


@pytest.mark.parametrize(
    ("surface", "message"),
    [
        ({"material": "chrome"}, "surface.material: unknown surface 'chrome'"),
        (
            {"specular_fraction": 1.5},
            "surface.specular_fraction: expected a number from 0 to 1, got 1.5",
        ),
        ({"reflectance": 0}, "surface.reflectance: expected a number > 0 and ≤ 1, got 0"),
        ({"specular_fraction_range": [0.5, 0.1]}, "0 ≤ min ≤ max ≤ 1"),
        (
            {"specular_fraction_range": "all"},
            "specular_fraction_range: expected a list of 2 numbers from 0 to 1, got 'all'",
        ),
        ({"gloss": 1}, "unknown key"),
    ],
)
def test_bad_surface_settings_are_named(surface, message):
    with pytest.raises(InputError) as err:
        parse_config({"surface": surface})
    assert message in str(err.value)


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        (
            "[search]\npopsize = 100000",
            "search.popsize: expected a whole number from 1 to 1000, got 100000",
        ),
        ("[search]\nworkers = 10000", "search.workers"),
        ("[search]\npolish_maxiter = 1000000000", "search.polish_maxiter"),
        (
            "[pareto]\nmargins_mm = [" + "0.1, " * 101 + "0.1]",
            "pareto.margins_mm: expected a list of 1 to 100 numbers from 0 to 1000 mm, "
            "got 102 items",
        ),
        (
            "[robust]\nmax_rounds = 1000000",
            "robust.max_rounds: expected a whole number from 1 to 100, got 1000000",
        ),
        ("[workspace]\nstep_deg = 1e-6", "workspace.step_deg = 1e-06°: asks for"),
        (
            "[mechanics]\nn_units = 2.5",
            "mechanics.n_units: expected a whole number from 1 to 1000, got 2.5",
        ),
    ],
)
def test_sizes_beyond_their_limits_are_refused(text, fragment):
    with pytest.raises(InputError) as exc:
        parse_config(tomllib.loads(text))
    assert fragment in str(exc.value)


def test_the_work_of_a_search_is_checked_before_it_starts():
    from reflector_opt.optimiser import optimise
    from reflector_opt.optimiser._search import check_search_work

    assert check_search_work(Problem(), SearchBudget()) < 10**8
    one = check_search_work(Problem(), SearchBudget())
    assert check_search_work(Problem(), SearchBudget(), starts=3) == 3 * one
    for budget, fragment in (
        (SearchBudget(grid_step_deg=1e-5), "search.grid_step_deg = 1e-05°"),
        (SearchBudget(polish_step_deg=1e-5), "search.polish_step_deg"),
        (SearchBudget(popsize=1000, maxiter=10_000), "search.popsize, search.maxiter and starts"),
    ):
        with pytest.raises(InputError) as exc:
            optimise(Problem(), budget=budget)
        assert fragment in str(exc.value)


@pytest.mark.parametrize("part", ["VCNT2020", "NJL5901R-2"])
def test_the_sensor_table_takes_any_catalogue_part(part):
    config = parse_config({"sensor": {"model": part}})
    assert config.problem.sensor.name == part


def test_an_unknown_sensor_names_the_presets_and_the_catalogue():
    with pytest.raises(InputError, match=r"sensor.model: .*VCNT2020"):
        parse_config({"sensor": {"model": "NOPE"}})
