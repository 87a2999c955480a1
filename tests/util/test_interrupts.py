"""A Ctrl-C during an import that swallows it is held and raised after the import."""

import importlib
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from reflector_opt.cli import _commands, main
from reflector_opt.util import _interrupts as interrupts
from reflector_opt.util._interrupts import CHECK_S, _importing, interrupts_after_imports

ROOT = Path(__file__).resolve().parents[2]

#: A module that interrupts itself while it is imported and, like trimesh's guarded
#: optional imports, swallows whatever is raised.
SWALLOWING = """
import os
import signal
SWALLOWED = False
try:
    os.kill(os.getpid(), signal.SIGINT)
    for _ in range(1000):  # the handler runs between these bytecodes
        pass
except BaseException:
    SWALLOWED = True
"""


@pytest.fixture
def swallowing(tmp_path, monkeypatch):
    """Import name of a fresh swallowing module, declared as one."""
    (tmp_path / "swallows_interrupt.py").write_text(SWALLOWING)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "swallows_interrupt", raising=False)
    monkeypatch.setattr(interrupts, "SWALLOWING_PACKAGES", ("swallows_interrupt",))
    return "swallows_interrupt"


def _wait_for_interrupt():
    deadline = time.monotonic() + 100 * CHECK_S
    while time.monotonic() < deadline:
        time.sleep(CHECK_S / 4)


def test_an_interrupt_during_an_import_is_swallowed_without_the_handler(swallowing):
    module = importlib.import_module(swallowing)
    assert module.SWALLOWED  # the case the handler is for: nothing was raised
    _wait_for_interrupt()  # and nothing is raised later either


def test_the_interrupt_is_held_during_the_import_and_raised_after_it(swallowing):
    with pytest.raises(KeyboardInterrupt), interrupts_after_imports():
        module = importlib.import_module(swallowing)
        assert not module.SWALLOWED  # the import ran to its end undisturbed
        _wait_for_interrupt()
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_outside_an_import_the_interrupt_is_raised_at_once():
    with pytest.raises(KeyboardInterrupt), interrupts_after_imports():
        signal.raise_signal(signal.SIGINT)
        for _ in range(1000):
            pass
        pytest.fail("the interrupt was not raised at once")


def test_sigterm_is_raised_as_terminated_and_its_handler_restored():
    with pytest.raises(interrupts.Terminated), interrupts_after_imports():
        signal.raise_signal(signal.SIGTERM)
        for _ in range(1000):
            pass
        pytest.fail("SIGTERM was not raised at once")
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL


def test_a_sigterm_during_a_swallowing_import_is_held_and_raised_as_terminated(
    swallowing, tmp_path
):
    (tmp_path / f"{swallowing}.py").write_text(SWALLOWING.replace("SIGINT", "SIGTERM"))
    with pytest.raises(interrupts.Terminated), interrupts_after_imports():
        module = importlib.import_module(swallowing)
        assert not module.SWALLOWED  # the import ran to its end undisturbed
        _wait_for_interrupt()


def test_only_the_import_of_a_swallowing_package_holds_the_interrupt(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    for name in ("reports_import", "other_import"):
        (tmp_path / f"{name}.py").write_text(
            "import sys\nfrom reflector_opt.util._interrupts import _importing\n"
            "DURING = _importing(sys._getframe(), ('reports_import',))\n"
            "ANY = _importing(sys._getframe())\n"
        )
        monkeypatch.delitem(sys.modules, name, raising=False)
    assert importlib.import_module("reports_import").DURING
    other = importlib.import_module("other_import")
    assert not other.DURING and other.ANY  # an import, but not of a swallowing package
    assert not _importing(sys._getframe()) and not _importing(sys._getframe(), ("pytest",))


def test_the_command_line_exits_130_after_an_import_that_swallowed_ctrl_c(
    swallowing, monkeypatch, capsys
):
    finished = []

    def run(args):
        importlib.import_module(swallowing)
        _wait_for_interrupt()
        finished.append(True)
        return 0

    monkeypatch.setattr(_commands, "run_export", run)
    assert main(["export", "design.json"]) == 130
    assert not finished
    assert capsys.readouterr().err.strip() == "reflector-opt: interrupted"


@pytest.mark.parametrize(
    ("signame", "code", "line"),
    [("SIGINT", 130, "interrupted"), ("SIGTERM", 143, "terminated")],
)
def test_a_stop_while_the_command_line_starts_is_one_line_and_its_code(signame, code, line):
    # The signal arrives while the command line's own modules are imported, before
    # ``main`` runs: deterministic, by signalling at the import of reflector_opt.cli.
    # (SIGTERM there was the default action: no line, killed by the signal.)
    program = (
        "import builtins, os, signal, sys\n"
        "from reflector_opt import __main__ as entry\n"
        "real = builtins.__import__\n"
        "def interrupting(name, *args, **kwargs):\n"
        "    if name == 'reflector_opt.cli':\n"
        f"        os.kill(os.getpid(), signal.{signame})\n"
        "    return real(name, *args, **kwargs)\n"
        "builtins.__import__ = interrupting\n"
        "sys.argv = ['reflector-opt', '--help']\n"
        "sys.exit(entry.run())\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", program], capture_output=True, text=True, cwd=ROOT, timeout=60
    )
    assert done.returncode == code
    assert done.stderr == f"reflector-opt: {line}\n" and done.stdout == ""
