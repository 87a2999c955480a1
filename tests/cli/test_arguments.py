"""One option vocabulary across the subcommands, and the deprecated spellings."""

import argparse
from pathlib import Path

import pytest

from reflector_opt.cli import build_parser, main
from reflector_opt.cli._arguments import DEFAULT_OUT, deprecated_alias, output_file


def _subparsers():
    parser = build_parser()
    (action,) = (a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return action.choices


SUBPARSERS = _subparsers()


def _options(sub):
    """Visible options of a subcommand parser: option string -> action."""
    return {
        s: a
        for a in sub._actions
        if a.help != argparse.SUPPRESS
        for s in a.option_strings
        if s.startswith("--")
    }


@pytest.mark.parametrize("name", sorted(SUBPARSERS))
def test_every_output_is_out_and_says_file_or_folder(name):
    """One spelling, -o/--out, for a folder (DIR) and for a file (FILE)."""
    options = _options(SUBPARSERS[name])
    if "--out" in options:
        out = options["--out"]
        assert out.option_strings == ["-o", "--out"] and out.metavar in ("DIR", "FILE")
        if out.metavar == "DIR":
            assert Path(out.default).parts[0] == DEFAULT_OUT, "every default output under cad_out/"
            assert out.help.startswith("folder for")
        else:
            assert out.type is output_file and out.help.startswith("file to write")
    assert not {"--output", "--out-dir", "--output-dir", "--folder", "--dir"} & set(options)


def test_every_subcommand_that_writes_names_its_output():
    writers = {n for n, sub in SUBPARSERS.items() if "--out" in _options(sub)}
    assert writers == set(SUBPARSERS) - {"evaluate"}  # evaluate only prints


@pytest.mark.parametrize("name", ["calibrate", "estimate", "fit-sensor", "identify"])
def test_the_former_output_spelling_of_a_file_still_works(name, capsys):
    argv = [name, *_required(name), "--output", "written.json"]
    assert build_parser().parse_args(argv).output == "written.json"
    assert "warning: --output is deprecated; use -o/--out" in capsys.readouterr().err


def test_same_option_same_meaning():
    """An option spelled alike takes the same kind of value in every subcommand."""
    seen = {}
    for name, sub in SUBPARSERS.items():
        for option, action in _options(sub).items():
            if option in ("--out", "--output", "--help", "--design"):
                continue  # --out and --output checked above; --design is an input file
            value_type = getattr(action.type, "__qualname__", None)  # count(…) and count(…) alike
            kind = (action.metavar, value_type, action.nargs, type(action).__name__)
            seen.setdefault(option, {})[name] = kind
    for option, kinds in seen.items():
        assert len(set(kinds.values())) == 1, (option, kinds)


@pytest.mark.parametrize("name", sorted(SUBPARSERS))
def test_every_subcommand_takes_quiet_and_verbose(name):
    options = _options(SUBPARSERS[name])
    assert options["--quiet"].option_strings == ["-q", "--quiet"]
    assert options["--verbose"].option_strings == ["-v", "--verbose"]
    args = build_parser().parse_args([name, *_required(name), "-vv"])
    assert args.verbose == 2 and args.quiet is False


def _required(name):
    """Placeholder values of a subcommand's required arguments."""
    sub = SUBPARSERS[name]
    values = []
    for action in sub._actions:
        if not action.option_strings and action.nargs in (None, "+"):
            values.append("x.json")
        elif action.required:
            values += [action.option_strings[-1], "x=1" if action.dest == "vary" else "x.json"]
    return values


def test_settings_files_are_config():
    for name, sub in SUBPARSERS.items():
        options = _options(sub)
        toml = {o for o, a in options.items() if str(a.metavar).endswith(".toml")}
        # --conditions names the operating conditions, a file of its own kind (docs/conditions.md)
        assert toml <= {"--config", "--tolerances", "--conditions"}, (name, toml)


def test_old_spelling_still_works_with_a_warning(capsys):
    parser = argparse.ArgumentParser(prog="demo")
    parser.add_argument("-o", "--out", metavar="DIR", default="cad_out")
    deprecated_alias(parser, "--output", "--out")
    assert parser.parse_args(["--output", "x"]).out == "x"
    assert capsys.readouterr().err == "demo: warning: --output is deprecated; use -o/--out\n"
    assert parser.parse_args([]).out == "cad_out"
    assert "--output" not in parser.format_help()
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize(
    ("old", "new", "dest", "value"),
    [
        ("--output", "-o/--out", "out", "parts"),
        ("--tolerance", "--chord-tolerance", "chord_tolerance_mm", "0.02"),
        ("--params", "--config", "config", "cad.toml"),
    ],
)
def test_export_keeps_its_old_spellings_hidden(old, new, dest, value, capsys):
    args = build_parser().parse_args(["export", "design.json", old, value])
    assert str(getattr(args, dest)) == value  # the text, converted by the declaration
    assert f"warning: {old} is deprecated; use {new}" in capsys.readouterr().err
    assert old + " " not in SUBPARSERS["export"].format_help()


def test_help_of_no_cad_names_what_is_skipped(capsys):
    with pytest.raises(SystemExit):
        main(["report", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--no-cad" in text and "about 6 s" not in text
    assert "do not write the printable parts (STL, 3MF, previews)" in text


@pytest.fixture(scope="module")
def lab_files(tmp_path_factory):
    """A calibration CSV, its coefficients, a voltage log and a sensor curve."""
    from tests.labfiles import write_lab_files

    folder = tmp_path_factory.mktemp("lab")
    write_lab_files(folder)
    rows = "".join(f"{0.4 + 0.4 * i},{2.5 - 0.2 * i}\n" for i in range(8))
    (folder / "curve.csv").write_text("distance_mm,volts\n" + rows)
    return folder


@pytest.mark.parametrize(
    ("argv", "target", "name"),
    [
        (["calibrate", "data.csv", "-o", "data.csv"], "data.csv", "data"),
        (["calibrate", "data.csv", "-o", "link.csv"], "data.csv", "data"),  # a link to it
        (["estimate", "coef.json", "log.csv", "-o", "log.csv"], "log.csv", "log"),
        (["estimate", "coef.json", "log.csv", "-o", "coef.json"], "coef.json", "coefficients"),
        (["fit-sensor", "curve.csv", "-o", "curve.csv"], "curve.csv", "curve"),
        (["fit-sensor", "curve.csv", "--material", "-o", "curve.csv"], "curve.csv", "curve"),
    ],
)
def test_an_output_over_an_input_is_refused_and_the_input_kept(
    lab_files, tmp_path, monkeypatch, capsys, argv, target, name
):
    """``calibrate data.csv -o data.csv`` replaced the measurements with the coefficients."""
    for path in lab_files.iterdir():
        (tmp_path / path.name).write_bytes(path.read_bytes())
    (tmp_path / "link.csv").symlink_to("data.csv")
    monkeypatch.chdir(tmp_path)
    before = (tmp_path / target).read_bytes()
    assert main(argv) == 2
    err = capsys.readouterr().err
    output = argv[argv.index("-o") + 1]
    assert err.count("\n") == 1 and f"--out {output}: is the input {name} ({target})" in err
    assert (tmp_path / target).read_bytes() == before


def test_fit_sensor_may_update_its_design_in_place(lab_files, tmp_path, capsys):
    from reflector_opt.design import default_design, load_design

    design = tmp_path / "design.json"
    default_design().save(design)
    argv = ["fit-sensor", lab_files / "curve.csv", "--design", design, "-o", design, "-q"]
    assert main([str(a) for a in argv]) == 0
    assert load_design(design).sensors[0].model == "NJL5901R-2-measured"


@pytest.mark.parametrize("name", sorted(SUBPARSERS))
def test_an_unknown_argument_is_reported_by_the_subcommand(name, capsys):
    """argparse reported it as 'reflector-opt: error: …', without the subcommand."""
    with pytest.raises(SystemExit) as exit_:
        build_parser().parse_args([name, *_required(name), "--bogus=7"])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err == f"reflector-opt {name}: error: unrecognized arguments: --bogus=7\n"


@pytest.mark.parametrize("name", sorted(SUBPARSERS))
def test_a_design_is_named_alike_in_every_help(name):
    """``design`` in some helps and ``DESIGN.json`` in others read as two different inputs."""
    for action in SUBPARSERS[name]._actions:
        if action.dest == "design":
            assert action.metavar == "DESIGN.json", (name, action.option_strings)


@pytest.mark.parametrize("name", sorted(SUBPARSERS))
def test_every_subcommand_can_print_its_summary_as_json(name):
    action = _options(SUBPARSERS[name]).get("--json")
    assert action is not None and action.nargs == 0 and action.default is False


@pytest.mark.parametrize(
    "argv",
    [
        ["evaluate", "--cond", "examples/conditions.toml"],
        ["optimise", "--cond", "examples/conditions.toml"],
        ["evaluate", "--no-pred"],
    ],
)
def test_an_abbreviated_option_is_refused(argv, capsys):
    """argparse would take ``--cond`` for ``--conditions``; a typo must not pass for an
    option."""
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    assert "unrecognized arguments" in capsys.readouterr().err
