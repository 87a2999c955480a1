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


@pytest.fixture(scope="session")
def design():
    """The built-in default design."""
    return default_design()
