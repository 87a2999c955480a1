"""Shared fixtures of the workflow tests."""

import pytest

import reflector_opt as ro
from reflector_opt.design import Workspace


@pytest.fixture(scope="module")
def coarse_design(tmp_path_factory):
    """The default design on a 2° grid (the report's simulations then take seconds), saved."""
    path = tmp_path_factory.mktemp("design") / "design.json"
    ro.default_design().replace(workspace=Workspace(step_deg=2.0)).save(path)
    return path
