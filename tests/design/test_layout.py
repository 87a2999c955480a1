"""The printable parts' layout (design.layout): the reflecting shell, the bearing's clearance
and the patches' bands around the points the sensors see."""

import pytest

from reflector_opt.design._layout import plan_layout
from reflector_opt.util._errors import InputError
from tests.cad.designs import DESIGN_A, DESIGN_B, printable_design


@pytest.fixture(scope="module", params=["A", "B"])
def layout(request):
    return plan_layout({"A": DESIGN_A, "B": DESIGN_B}[request.param])


def test_concentric_shell_is_the_radius_difference():
    design = printable_design(9.0, (0.0, 0.0, 0.0), 10.0)
    assert plan_layout(design).reflector_walls_mm["reflecting shell"] == pytest.approx(
        1.5, abs=1e-9
    )


def test_band_covers_every_seen_point_plus_margin(layout):
    for patch in layout.patches:
        lo, hi = patch.seen_elevation_deg
        assert patch.elevation_deg[0] < lo and patch.elevation_deg[1] > hi
        assert (
            patch.azimuth_deg[0]
            < patch.seen_azimuth_deg[0]
            <= patch.seen_azimuth_deg[1]
            < patch.azimuth_deg[1]
        )
        assert patch.margin_mm > 1.0  # 1.5 × the ~0.9 mm beam footprint + 0.2 mm


def test_bearing_must_clear_the_inner_surface():
    with pytest.raises(InputError, match="does not clear the bearing's outer ring"):
        plan_layout(printable_design(9.0, (0.0, 0.0, -1.2), 10.0, inner=7.3))
