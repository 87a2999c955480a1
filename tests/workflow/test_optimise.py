"""The optimise run writes what the command writes, and refuses options that cannot work."""

import json
from pathlib import Path

import pytest

import reflector_opt as ro
from reflector_opt.cli import main
from reflector_opt.optimise.config import load_config
from reflector_opt.util.errors import InputError
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


def test_optimise_run_writes_what_the_command_writes(config, tmp_path, capsys):
    by_command, by_call = tmp_path / "command", tmp_path / "call"
    args = ["optimise", "--config", str(config), "--seed", "3", "--no-report", "--quiet"]
    assert main([*args, "--json", "-o", str(by_command)]) == 0
    printed = json.loads(capsys.readouterr().out)

    # the config as the command reads it, given as an object: the same run
    options = ro.OptimiseOptions(config=load_config(config), seed=3, report=False)
    run = ro.optimise_run(options, out=by_call)
    assert _without_timing(by_call / "design.json") == _without_timing(by_command / "design.json")
    assert run.files == [by_call / "design.json"] and run.design.predicted["optimiser"]["seed"] == 3
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
        ({"starts": 0}, "--starts: 0 is not a whole number from 1 to 256"),
        ({"seed": -1}, "--seed: expected a whole number ≥ 0, got -1"),
        ({"workers": 1.5}, "--workers: 1.5 is not a whole number"),
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
        ro.optimise_run(ro.OptimiseOptions(**options), out=tmp_path / "out")
    assert not (tmp_path / "out").exists()
