"""The library logs through :mod:`logging` and never prints; only the command line prints."""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "reflector_opt"
#: The command line: the ``cli`` package and ``__main__``, the console script's entry.
COMMAND_LINE = ("cli", "__main__.py")
LIBRARY = sorted(
    p for p in PACKAGE.rglob("*.py") if not set(COMMAND_LINE) & set(p.relative_to(PACKAGE).parts)
)


def _calls(path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [node for node in ast.walk(tree) if isinstance(node, ast.Call)]


def _name(func):
    if isinstance(func, ast.Name):
        return func.id
    if isinstance(func, ast.Attribute):
        return f"{_name(func.value)}.{func.attr}"
    return ""


@pytest.mark.parametrize("path", LIBRARY, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_library_module_does_not_print(path):
    written = [
        f"line {c.lineno}: {_name(c.func)}"
        for c in _calls(path)
        if _name(c.func) in ("print", "sys.stdout.write", "sys.stderr.write", "pprint")
    ]
    assert not written, f"log through logging.getLogger(__name__) instead: {written}"


@pytest.mark.parametrize("path", LIBRARY, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_loggers_are_named_after_their_module(path):
    for call in _calls(path):
        if _name(call.func) == "logging.getLogger":
            (arg,) = call.args
            assert isinstance(arg, ast.Name) and arg.id == "__name__", f"line {call.lineno}"


def test_the_check_finds_a_print(tmp_path):
    module = tmp_path / "m.py"
    module.write_text("import sys\nprint('x')\nsys.stderr.write('y')\n")
    assert [_name(c.func) for c in _calls(module)] == ["print", "sys.stderr.write"]
