"""Fixtures shared by the CAD tests."""

import pytest

from reflector_opt.cad import build_parts, check_collisions, plan_layout
from tests.cad.designs import COARSE, DESIGN_A, DESIGN_B


@pytest.fixture(scope="package", params=["A", "B"])
def built(request):
    """Printable designs A and B: (design, layout, parts at the chord tolerance COARSE, their
    collision report); built once for every CAD test module."""
    design = {"A": DESIGN_A, "B": DESIGN_B}[request.param]
    layout = plan_layout(design)
    parts = build_parts(design, layout, COARSE)
    collision = check_collisions(parts, design)
    return design, layout, parts, collision
