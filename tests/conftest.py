"""Shared fixtures."""

import matplotlib
import pytest

matplotlib.use("Agg")

from reflector_opt import default_design


@pytest.fixture(scope="session")
def design():
    """The built-in default design."""
    return default_design()
