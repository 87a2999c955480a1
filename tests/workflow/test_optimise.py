"""The optimise run writes what the command writes, and refuses options that cannot work."""

import json
from pathlib import Path

import pytest
from msgspec import UNSET

import reflector_opt as ro
from reflector_opt.cli import main
from reflector_opt.optimiser._config import load_config
from reflector_opt.util._errors import InputError
from tests.searchsettings import write_settings

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def config(tmp_path_factory):
    return write_settings(tmp_path_factory.mktemp("config"))


def _without_timing(path):
    """design.json as a dict, without the search's wall times (the one part a rerun changes)."""
    data = json.loads(Path(path).read_text(encoding="utf-8"))
    del data["predicted"]["optimiser"]["seconds"]
    return data


def test_optimise_writes_what_the_command_writes(config, tmp_path, capsys):
    by_command, by_call = tmp_path / "command", tmp_path / "call"
    args = ["optimise", "--config", str(config), "--seed", "3", "--no-report", "--quiet"]
    assert main([*args, "--json", "-o", str(by_command)]) == 0
    printed = json.loads(capsys.readouterr().out)

    # the config as the command reads it, given as an object: the same run
    options = ro.OptimiseOptions(config=load_config(config), seed=3, report=False)
    run = ro.optimise(options).write(by_call)
    assert _without_timing(by_call / "design.json") == _without_timing(by_command / "design.json")
    assert run.files == (by_call / "design.json",)
    assert run.design.predicted.optimiser["seed"] == 3
    # --json is the run's summary: the design as design.json holds it, and the files written
    assert printed["files"] == [str(by_command / "design.json")]
    assert (
        printed["design"]["reflector"]
        == json.loads((by_command / "design.json").read_text(encoding="utf-8"))["reflector"]
    )
    assert printed["predicted"] is None and printed["cad"]["written"] is False
    assert repr(run) == run.text() and repr(run).startswith("optimised design (seed 3, ")
    # a notebook shows what the command prints; no tolerance file, none named
    assert run._repr_html_().startswith("<pre>optimised design (seed 3, ")
    assert run.tolerances is None
    manifest = json.loads((by_call / "manifest.json").read_text(encoding="utf-8"))
    assert manifest["command"][1] == "optimise"  # a later `reflector-opt optimise` replaces it


@pytest.mark.parametrize(
    ("options", "fragment"),
    [
        ({"starts": 0}, "--starts: expected a whole number from 1 to 256, got 0"),
        ({"seed": -1}, "--seed: expected a whole number from 0 to 4294967295, got -1"),
        ({"workers": 1.5}, "--workers: expected a whole number from 1 to 256, got 1.5"),
        ({"surface": "chrome"}, "chrome"),
        (
            {"starts": 2, "tolerances": ROOT / "examples" / "tolerance.toml"},
            "not with --tolerances",
        ),
        ({"scheduler": "tcp://127.0.0.1:1"}, "give --starts N or --tolerances"),
    ],
)
def test_options_that_cannot_work_are_refused_before_any_work(tmp_path, options, fragment):
    with pytest.raises(InputError, match=fragment.replace("-", r"\-")):
        ro.optimise(ro.OptimiseOptions(**options))
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("options", "fragment"),
    [
        (
            {"objective": "white-noise"},
            "--objective: expected one of 'in-use', 'resolution', got 'white-noise'",
        ),
        ({"read_out": "auto"}, "--read-out: expected one of 'chosen', 'stated', got 'auto'"),
    ],
)
def test_an_unknown_objective_or_read_out_is_refused_before_any_work(tmp_path, options, fragment):
    with pytest.raises(InputError, match=fragment.replace("-", r"\-")):
        ro.optimise(ro.OptimiseOptions(**options))
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("argv", [["--objective", "nan"], ["--read-out", "best"]])
def test_the_command_refuses_an_unknown_objective_in_one_line(tmp_path, capsys, argv):
    assert main(["optimise", *argv, "-o", str(tmp_path / "out")]) == 2
    assert not (tmp_path / "out").exists()
    err = capsys.readouterr().err
    assert err.startswith(f"reflector-opt optimise: error: {argv[0]}: expected one of ")
    assert f"got '{argv[1]}'" in err and err.count("\n") == 1


@pytest.fixture(scope="module")
def in_use_and_resolution(config, tmp_path_factory):
    """The small search's run by default (in use, read-out chosen) and with the white-noise
    objective, both judged in the default conditions."""
    folder = tmp_path_factory.mktemp("objectives")
    runs = {}
    for objective in ("in-use", "resolution"):
        options = ro.OptimiseOptions(config=config, objective=objective, report=False)
        runs[objective] = ro.optimise(options).write(folder / objective)
    return runs


def test_the_default_objective_is_the_error_in_use_with_the_read_out_chosen(
    in_use_and_resolution,
):
    from reflector_opt.analysis._budget import error_budget
    from reflector_opt.design._conditions import Conditions
    from reflector_opt.optimiser._conditions import median_total_deg

    run = in_use_and_resolution["in-use"]
    block = run.design.predicted.conditions
    chosen = block.read_out["chosen"]
    # the conditions written are the default ones with the read-out chosen
    read_out = {k: chosen[k] for k in ("drive", "sample_rate_hz", "temperature_compensated")}
    assert block.conditions == Conditions().replace(**read_out).to_dict()
    # the figures are the budget's of the design written, in them, on the budget's 1° grid
    budget = error_budget(run.design, Conditions().replace(**read_out))
    assert block.worst_case_deg == pytest.approx(budget.worst_case_deg, rel=1e-9)
    assert block.median_deg == pytest.approx(median_total_deg(budget), rel=1e-9)
    # the chosen read-out is the simplest within 5 % of the best candidate
    worst = [c["worst_case_deg"] for c in block.read_out["candidates"]]
    assert chosen["worst_case_deg"] <= min(worst) * 1.05
    # the improvement is in use, against the default design as stated (dc, uncompensated)
    base = error_budget(ro.default_design(), Conditions())
    assert block.baseline.worst_case_deg == pytest.approx(base.worst_case_deg, rel=1e-9)
    improvement = run.design.predicted.improvement
    assert improvement["basis"] == "in use"
    assert improvement["worst"] == pytest.approx(base.worst_case_deg / budget.worst_case_deg)
    assert "resolution" in improvement  # the white-noise ratios kept beside it


def test_the_resolution_objective_keeps_the_white_noise_search_and_is_judged_in_use(
    in_use_and_resolution, config
):
    from reflector_opt.analysis._budget import error_budget
    from reflector_opt.design._conditions import Conditions
    from reflector_opt.optimiser._evaluation import objective_value

    run = in_use_and_resolution["resolution"]
    predicted = run.design.predicted
    # the objective is the white-noise one of the design's own metrics
    weight = load_config(config).problem.isotropy_weight
    expected = objective_value(run.result.metrics, weight)
    assert predicted.objective_deg == pytest.approx(expected, rel=1e-12)
    # every headline in use: its improvement too, the white-noise one beside it
    assert predicted.improvement["basis"] == "in use"
    assert predicted.improvement["resolution"]["worst"] > 1.0
    # and the design is judged in the default conditions as stated, no read-out chosen
    block = predicted.conditions
    assert block.read_out is UNSET and block.conditions == Conditions().to_dict()
    budget = error_budget(run.design, Conditions())
    assert block.worst_case_deg == pytest.approx(budget.worst_case_deg, rel=1e-9)
    assert block.worst_case_deg > predicted.objective_deg  # in use above the floor
