"""Shared fixtures, and the property tests' settings."""

import os

import matplotlib
import pytest
from hypothesis import settings

matplotlib.use("Agg")

from reflector_opt import default_design

#: The property tests draw the same examples on every run ("repeatable", the default), so a
#: run of the suite is reproducible; ``HYPOTHESIS_PROFILE=explore`` draws new ones each run.
settings.register_profile("repeatable", derandomize=True)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))


def pytest_addoption(parser):
    parser.addoption(
        "--regenerate-golden",
        action="store_true",
        help="tests/test_outputs_unchanged.py: write the documented commands' outputs as the "
        "new golden copies instead of comparing them (only for an intended output change)",
    )


@pytest.fixture(scope="session")
def design():
    """The built-in default design."""
    return default_design()


@pytest.fixture(scope="session")
def documented_runs(tmp_path_factory):
    """The documented commands run so far (``tests/test_documented_commands.py``), so each runs
    once a session, whichever test needs it first: the scratch folder (``done``), the printed
    text (``printed``) and the files written (``written``) of each, by command line."""
    root = tmp_path_factory.mktemp("documented")
    return {"root": root, "done": {}, "printed": {}, "written": {}}
