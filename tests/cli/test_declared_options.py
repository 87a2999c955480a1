"""Every declared option of every command, given bad text, is refused by its declaration:
exit 2, one line naming the option, no traceback, nothing written; and the one check at the
boundary is the same for Python (a run's keyword argument) as for the command line."""

import msgspec.inspect as mi
import pytest

from reflector_opt.cli import build_parser, main
from reflector_opt.util._declared import checked, fields, meta_of
from reflector_opt.util._errors import InputError
from reflector_opt.workflow._calibrate import CalibrateOptions
from reflector_opt.workflow._options import OptimiseOptions

#: Text no number, choice or list option takes; a bounded number is also given far outside.
BAD = ("nan", "inf", "x", "1e400")

#: Each command's positional inputs, as files that need not exist: an option is checked first.
INPUTS = {
    "compare": ["a.json"],
    "correct": ["a.json"],
    "sweep": ["d.json", "--vary", "a=1"],
    "smallest": ["--target-deg", "1"],
}


def _refuses_text(kind, field):
    """Whether the declaration itself refuses text: a number, a choice, a list of numbers (a
    list of names or a file is checked by the run, where it is read)."""
    value = "x" if field.items is None else ["x"] * (field.items or 1)
    try:
        checked(kind, {field.name: value}, strict=False)
    except InputError as exc:
        return str(exc).startswith(field.flag)  # not another option's (one that is needed)
    return False


def _declared():
    """(command, field) for every declared option whose declaration refuses bad text."""
    parser = build_parser()
    for name, command in parser.commands.items():
        kinds = {a.declared_kind for a in command._actions if hasattr(a, "declared_kind")}
        for kind in kinds:
            for field in fields(kind):
                if not field.is_bool and _refuses_text(kind, field):
                    yield name, command, field


DECLARED = sorted(_declared(), key=lambda entry: (entry[0], entry[2].name))


def _argv(name, command, field, text):
    positional = [a for a in command._actions if not a.option_strings and a.nargs != "?"]
    inputs = INPUTS.get(name, ["in.csv"] * len(positional))
    values = [text] * (field.items or 1)
    return [name, *inputs, field.flag, *values]


def test_every_declared_number_is_bounded_on_both_sides():
    """Non-finite and absurd values are refused: every number a command takes states both
    ends of its range."""
    unbounded = []
    for command in build_parser().commands.values():
        for kind in {a.declared_kind for a in command._actions if hasattr(a, "declared_kind")}:
            for field in mi.type_info(kind).fields:
                info = meta_of(field.type)[1]
                if isinstance(info, mi.IntType | mi.FloatType):
                    low, high = (info.ge, info.gt), (info.le, info.lt)
                    if low == (None, None) or high == (None, None):
                        unbounded.append(f"{kind.__name__}.{field.name}")
    assert not unbounded


def test_the_sample_covers_every_command_and_kind():
    commands = {name for name, _, _ in DECLARED}
    assert len(commands) >= 14 and len(DECLARED) >= 40
    assert any(f.choices for _, _, f in DECLARED) and any(f.items for _, _, f in DECLARED)


@pytest.mark.parametrize(
    ("name", "command", "field"), DECLARED, ids=[f"{n}{f.flag}" for n, _, f in DECLARED]
)
def test_bad_text_for_any_option_is_one_line_naming_it(name, command, field, tmp_path, capsys):
    out = tmp_path / "out"
    for text in BAD:
        argv = _argv(name, command, field, text)
        if "-o" in {s for a in command._actions for s in a.option_strings}:
            argv += ["-o", str(out / "x")]
        code = main(argv)
        err = capsys.readouterr().err
        assert code == 2, (argv, err)
        assert err.count("\n") == 1 and "Traceback" not in err, err
        assert field.flag in err, err
    assert not out.exists()


@pytest.mark.parametrize(
    ("kind", "given", "message"),
    [
        (OptimiseOptions, {"starts": 0}, "--starts: expected a whole number from 1 to 256, got 0"),
        (OptimiseOptions, {"workers": True}, "--workers: expected a whole number"),
        (CalibrateOptions, {"folds": float("nan")}, "--folds: expected a whole number"),
        (CalibrateOptions, {"fit": "l1"}, "--fit: expected one of"),
    ],
)
def test_python_and_the_command_line_share_the_one_check(kind, given, message):
    with pytest.raises(InputError, match=message):
        checked(kind, given)


def test_an_option_no_run_declares_is_a_type_error():
    with pytest.raises(TypeError, match="unknown option"):
        checked(CalibrateOptions, {"fold": 3})
