"""The package and the command line start without loading the heavy modules.

``import reflector_opt`` and every ``reflector-opt … --help`` run in a fresh interpreter,
which then reports the modules it loaded; the times are measured in
``benchmarks/bench_startup.py``, not here.
"""

import importlib
import json
import subprocess
import sys
from pathlib import Path

import pytest

import reflector_opt
from reflector_opt.cli import SUBCOMMANDS, build_parser

ROOT = Path(__file__).resolve().parents[1]

#: Modules that take a large share of a second to import; none may load at start-up.
HEAVY = (
    "numpy",  # a tenth of a second alone: the parser's choices and defaults do without it
    "numba",
    "matplotlib",
    "scipy.optimize",
    "scipy.interpolate",
    "trimesh",
    "manifold3d",
    "distributed",
    "cvxpy",
    "websockets",  # stream --view's server, imported when it starts
)

LAZY_PACKAGES = (
    "reflector_opt",
    "reflector_opt.design",
    "reflector_opt.calibration",
    "reflector_opt.tolerance",
    "reflector_opt.optimiser",
    "reflector_opt.cad",
)


def _loaded_after(code):
    """The heavy modules loaded by running ``code`` in a fresh interpreter."""
    probe = (
        "import json, sys\n"
        f"{code}\n"
        f"print(json.dumps([m for m in {list(HEAVY)!r} if m in sys.modules]))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", probe], cwd=ROOT, capture_output=True, text=True, check=True
    )
    return json.loads(done.stdout.splitlines()[-1])


def _help_code(argv):
    return (
        "import contextlib, io\n"
        "from reflector_opt.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):\n"
        f"    main({argv!r})"
    )


def test_import_loads_no_heavy_module():
    assert _loaded_after("import reflector_opt") == []


def _subcommands():
    return sorted(build_parser()._subparsers._group_actions[0].choices)


def test_every_subcommand_is_probed():
    assert len(_subcommands()) == len(SUBCOMMANDS)


@pytest.mark.parametrize("argv", [["--help"], *([name, "--help"] for name in _subcommands())])
def test_help_loads_no_heavy_module(argv):
    assert _loaded_after(_help_code(argv)) == []


def test_help_still_runs():
    done = subprocess.run(
        [sys.executable, "-m", "reflector_opt", "export", "--help"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    assert "usage: reflector-opt export" in done.stdout


@pytest.mark.parametrize("package", LAZY_PACKAGES)
def test_every_public_name_resolves_and_is_listed(package):
    module = importlib.import_module(package)
    lazy = {name: source for source, names in module._MODULES.items() for name in names}
    assert len(lazy) == sum(map(len, module._MODULES.values())), "a name under two modules"
    assert set(lazy) <= set(module.__all__), package
    for name in module.__all__:
        value = getattr(module, name)
        if name in lazy:
            assert value is getattr(importlib.import_module(f"{package}.{lazy[name]}"), name)
        assert name in dir(module)


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="not_a_name"):
        reflector_opt.not_a_name  # noqa: B018
    assert not hasattr(reflector_opt, "not_a_name")


def test_star_import_gives_the_public_api():
    namespace = {}
    exec("from reflector_opt import *", namespace)
    assert {name for name in namespace if not name.startswith("__")} == set(reflector_opt.__all__)
