"""reflector_opt.workflow._options: the options of an optimisation resolved and checked."""

import pytest

from reflector_opt.design._conditions import Conditions
from reflector_opt.optimiser._config import parse_config
from reflector_opt.util._declared import checked
from reflector_opt.util._errors import InputError
from reflector_opt.workflow._options import OptimiseOptions, prepare


def test_the_config_table_and_the_option_give_the_problem_its_conditions(tmp_path):
    config = parse_config({"conditions": {"temperature_range_k": 3.0, "drive": "modulated"}})
    assert config.problem.conditions == Conditions().replace(
        temperature_range_k=3.0, drive="modulated"
    )
    assert parse_config({}).problem.conditions is None
    path = tmp_path / "cond.toml"
    path.write_text("[conditions]\ntemperature_range_k = 7.0\n", encoding="utf-8")
    prepared = prepare(OptimiseOptions(config=config, conditions=str(path)))
    assert prepared.config.problem.conditions.temperature_range_k == 7.0  # the option wins
    assert prepared.config.problem.conditions.drive == "dc"  # the file's, not the config's
    assert prepare(OptimiseOptions(config=config)).config.problem.conditions.drive == "modulated"
    with pytest.raises(InputError, match="--conditions: expected Conditions"):
        prepare(OptimiseOptions(conditions=5.0))


def test_the_drift_front_needs_one_part():
    with pytest.raises(InputError, match="not with --drift-front"):
        prepare(OptimiseOptions(sensor="NJL5901R-2,VCNT2020", drift_front=True))


def test_the_options_override_the_config_and_one_part_sets_the_problems_sensor():
    config = parse_config({"search": {"seed": 4}})
    prepared = prepare(OptimiseOptions(config=config))
    assert (prepared.seed, prepared.parts, prepared.tolerance) == (4, [], None)
    prepared = prepare(OptimiseOptions(config=config, seed=9, surface="matte", workers=3))
    assert prepared.seed == 9 and prepared.config.budget.workers == 3
    assert prepared.config.problem.surface.name == "matte"
    prepared = prepare(OptimiseOptions(sensor="VCNT2020"))
    assert [part.name for part in prepared.parts] == ["VCNT2020"]
    assert prepared.config.problem.sensor.name == "VCNT2020"


@pytest.mark.parametrize(
    ("options", "fragment"),
    [
        ({"seed": -1}, "--seed: expected a whole number from 0 to 4294967295, got -1"),
        ({"seed": True}, "--seed: expected a whole number"),
        ({"starts": 0}, "--starts: expected a whole number from 1 to 256, got 0"),
        ({"starts": 257}, "--starts: expected a whole number from 1 to 256, got 257"),
        ({"workers": 2.0}, "--workers: expected a whole number from 1 to 256, got 2.0"),
        ({"starts": 2, "tolerances": object()}, "--starts: not with --tolerances"),
        ({"sensor": "NJL5901R-2,VCNT2020", "pareto": True}, "2 parts, not with --pareto"),
        ({"scheduler": "tcp://127.0.0.1:8786"}, "--scheduler runs the searches of --starts"),
    ],
)
def test_options_that_cannot_be_run_are_refused_naming_the_option(options, fragment):
    """Each option alone by its declaration (:func:`~reflector_opt.util._declared.checked`),
    the options together by :func:`prepare`."""
    with pytest.raises(InputError, match=fragment):
        prepare(checked(OptimiseOptions, options))
