"""An earlier public module path imports for one release, with a DeprecationWarning, and gives
the private module's names; a path that never existed is still refused."""

import importlib
import subprocess
import sys

import pytest


def test_an_earlier_module_path_warns_and_gives_the_private_modules_names():
    # in a fresh interpreter: this one may have imported the path already
    program = (
        "import warnings\n"
        "warnings.simplefilter('always')\n"
        "with warnings.catch_warnings(record=True) as caught:\n"
        "    from reflector_opt.design.design import Design\n"
        "from reflector_opt.design import _design\n"
        "assert Design is _design.Design\n"
        "print([str(w.message) for w in caught if w.category is DeprecationWarning])\n"
    )
    done = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "reflector_opt.design.design is deprecated" in done.stdout
    assert "import its names from reflector_opt.design" in done.stdout


def test_a_path_that_never_was_a_module_is_not_found():
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("reflector_opt.design.no_such_module")
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("reflector_opt.design._no_such_module")
