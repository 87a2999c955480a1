"""One option name per kind of input file across the subcommands (issue 37, item 6)."""

import argparse

import pytest

from reflector_opt.cli import build_parser

#: The commands that read a tolerance file (tolerances, the study's settings and targets).
TOLERANCE_READERS = ("identify", "optimise", "sweep", "tolerance")


def _subparsers():
    parser = build_parser()
    (action,) = (a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return action.choices


def _visible(sub):
    return {s: a for a in sub._actions if a.help != argparse.SUPPRESS for s in a.option_strings}


@pytest.mark.parametrize("name", TOLERANCE_READERS)
def test_the_tolerance_file_is_tolerances_in_every_command(name):
    """tolerance and sweep named it --config, optimise and identify --tolerances."""
    options = _visible(_subparsers()[name])
    assert options["--tolerances"].metavar == "FILE.toml"
    config = options.get("--config")
    assert config is None or "tolerance" not in config.help


@pytest.mark.parametrize("name", ["sweep", "tolerance"])
def test_the_former_config_of_a_tolerance_file_warns_in_one_line(name, capsys):
    argv = [name, "design.json", "--config", "tol.toml"]
    if name == "sweep":
        argv += ["--vary", "reflector.radius_mm=8"]
    assert build_parser().parse_args(argv).tolerances == "tol.toml"
    err = capsys.readouterr().err
    assert err == f"reflector-opt {name}: warning: --config is deprecated; use --tolerances\n"
    assert "--config" not in _subparsers()[name].format_help()


def test_one_meaning_per_file_option():
    """Where two commands read the same kind of file, they use the same option name."""
    kinds = {}
    for sub in _subparsers().values():
        for option, action in _visible(sub).items():
            if option.startswith("--") and str(action.metavar).endswith((".toml", ".json")):
                kinds.setdefault(action.metavar, set()).add(option)
    assert kinds["COND.toml"] == {"--conditions"}
    assert kinds["DESIGN.json"] == {"--design"}
    assert kinds["FILE.toml"] == {"--config", "--tolerances"}
