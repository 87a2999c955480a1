"""The layout's designed walls against the walls measured on the exported meshes.

The layout (:func:`reflector_opt.design._layout.plan_layout`) is what the optimiser trusts; the
mesh measurements (:func:`reflector_opt.cad._printability.shell_thickness_on_mesh`, the inward
rays of :func:`~reflector_opt.cad._printability.mesh_wall_thickness`) are the independent path.
They must agree to the chord tolerance, for the paper's unit on its GE 6 E and for a 20 mm
unit on the GE 4 E (the smallest unit of the ±90° segment of docs/smallest.md, whose patches
hang lower than the default's and whose sensors look up: its shell was once cut by the
envelope's floor at the shaft's end, 0.545 mm on the mesh against 0.823 mm designed, and its
body's strip channels cut 0.71 mm into the wall behind them).

Also: the default design's shell by hand, printable with its centre 1.4 mm below O and too
thin with the earlier 1.5 mm (reported); the printable designs A and B pass every check.
"""

import math

import numpy as np
import pytest

from reflector_opt.cad import build_parts, check_printability, plan_layout, to_trimesh
from reflector_opt.cad._printability import mesh_wall_thickness, shell_thickness_on_mesh
from reflector_opt.design import Mechanics, Reflector, SensorPlacement, Workspace, default_design
from reflector_opt.design._polar import distance_to_sphere, polar_directions
from tests.cad.designs import COARSE

TOLERANCE_MM = 0.02  # chord tolerance of the meshes, mm

#: The VCNT2020 unit of ``reflector-opt smallest --target-deg 0.1 --sensor VCNT2020
#: --segment-range-deg 90`` (8 units of ±11.25° on the GE 4 E, 20 mm), rounded.
SMALL_GE4E = default_design().replace(
    reflector=Reflector(7.3769, (0.6568, 0.0, -1.1459), 6.5, 0.9, 0.05),
    sensors=tuple(
        SensorPlacement(
            name, "VCNT2020", (6.4769, sign * 5.9573, -2.0), (-0.7156, -sign * 0.6582, 0.2338)
        )
        for name, sign in (("S1", -1.0), ("S2", 1.0))
    ),
    workspace=Workspace((-11.25, 11.25), (-11.25, 11.25), 0.1),
    mechanics=Mechanics(unit_diameter_mm=20.0, n_units=8, bearing="GE4E"),
)

DESIGNS = {"default": default_design(), "20 mm on GE 4 E": SMALL_GE4E}


@pytest.fixture(scope="module", params=list(DESIGNS))
def measured(request):
    design = DESIGNS[request.param]
    layout = plan_layout(design)
    solid = build_parts(design, layout, TOLERANCE_MM, parts=("reflector",)).reflector
    return design, layout, solid, to_trimesh(solid)


def test_the_designed_shell_is_the_shell_on_the_mesh(measured):
    _, layout, _, mesh = measured
    designed = layout.reflector_walls_mm["reflecting shell"]
    assert shell_thickness_on_mesh(mesh, layout, TOLERANCE_MM) == pytest.approx(
        designed, abs=TOLERANCE_MM
    )


def test_no_wall_on_the_mesh_is_thinner_than_designed(measured):
    _, layout, solid, mesh = measured
    thinnest = min(layout.reflector_walls_mm.values())
    assert mesh_wall_thickness(solid)[0] >= thinnest - TOLERANCE_MM
    report = check_printability("reflector", solid, mesh, layout, TOLERANCE_MM)
    assert report.shell_mesh_mm >= thinnest - TOLERANCE_MM
    # the mesh reaches as low as the patches' reflecting surface: nothing cut off below
    lowest = min(p.lowest_z_mm for p in layout.patches)
    assert mesh.bounds[0, 2] <= lowest + TOLERANCE_MM


def test_no_wall_of_the_body_on_the_mesh_is_thinner_than_designed():
    # The ±90° unit's sensors look 13.5° up: the strip channel, whose floor is the pad plane
    # normal to the axis, was once moved straight up to mid-height, which moved its floor
    # 0.71 mm into the wall behind it (0.48 mm on the mesh against 0.84 mm designed).
    layout = plan_layout(SMALL_GE4E)
    body = build_parts(SMALL_GE4E, layout, TOLERANCE_MM, parts=("body",)).body
    assert mesh_wall_thickness(body)[0] >= min(layout.body_walls_mm.values()) - TOLERANCE_MM


def test_the_small_unit_is_printable():
    layout = plan_layout(SMALL_GE4E)
    assert min(layout.reflector_walls_mm.values()) >= 0.8
    assert min(layout.body_walls_mm.values()) >= 0.8 - 1e-6


def test_the_shell_is_thinnest_at_the_patch_outline_for_the_small_unit():
    # Independent path: the shell as the least distance between the two surfaces, sampled
    # densely on both (inner sphere r_i about O, reflecting sphere about s0 over the patch).
    design = SMALL_GE4E
    layout = plan_layout(design)
    refl, s0 = design.reflector, np.asarray(design.reflector.centre_mm)
    patch = layout.patches[1]
    e = np.linspace(*patch.elevation_deg, 61)
    a = np.linspace(*patch.azimuth_deg, 61)
    u = polar_directions(e[:, None], a[None, :]).reshape(-1, 3)
    inner = refl.inner_radius_mm * u
    outer = distance_to_sphere(u, s0, refl.radius_mm)[:, None] * u
    # the nearest pairs lie near the corner of the band's top and the far azimuth edge
    near = np.argsort(np.linalg.norm(inner - outer, axis=1))[:200]
    pairs = np.linalg.norm(inner[near][:, None, :] - outer[None, :, :], axis=-1)
    sampled = float(pairs.min())
    designed = layout.reflector_walls_mm["reflecting shell"]
    step = math.radians(np.diff(e)[0]) * refl.radius_mm  # spacing of the samples, mm
    assert designed <= sampled <= designed + step


def _shell_at_band_top(h, band_top_deg):
    """Hand formula: the shell is thinnest at the band's top edge e, where the reflecting
    surface ends under the dome. Its edge lies t = −h sin e + sqrt(r_s² − h² cos² e) from O
    (the far root of |t·u − s0| = r_s, s0 = (0, 0, −h)), right above the inner surface's edge
    r_i·u: the wall is t − r_i (r_s = 9, r_i = 7.5 mm)."""
    e = math.radians(band_top_deg)
    return -h * math.sin(e) + math.sqrt(9.0**2 - (h * math.cos(e)) ** 2) - 7.5


@pytest.mark.parametrize(("h", "printable"), [(1.4, True), (1.5, False)])
def test_the_default_shell_by_hand_and_reported(h, printable):
    """The default (centre 1.4 mm below O) reaches the 0.8 mm wall; the same unit with its
    earlier centre, 1.5 mm below O, does not (0.751 mm), and is refused with the figure."""
    design = default_design()
    if not printable:
        design = design.replace(reflector=Reflector(centre_mm=(0.0, 0.0, -h)))
    assert design.reflector.centre_mm == (0.0, 0.0, -h)
    layout = plan_layout(design)
    shell = layout.reflector_walls_mm["reflecting shell"]
    assert shell == pytest.approx(_shell_at_band_top(h, layout.band_top_deg), abs=1e-9)
    # The sphere's nearest point to r_i·u, at r_s − sqrt(r_i² + h² + 2 r_i h sin e), lies above
    # the band's top, under the dome: not on the part.
    e = math.radians(layout.band_top_deg)
    assert 9.0 - math.sqrt(7.5**2 + h**2 + 2 * 7.5 * h * math.sin(e)) < shell - 0.005
    assert (shell >= 0.8) == printable and 0.70 < shell < 0.9
    parts = build_parts(design, layout, COARSE, parts=("reflector",))
    mesh = to_trimesh(parts.reflector)
    # The mesh measures the same wall, to within the chord tolerance.
    assert shell_thickness_on_mesh(mesh, layout, COARSE) == pytest.approx(shell, abs=COARSE)
    report = check_printability("reflector", parts.reflector, mesh, layout, COARSE)
    assert report.ok == printable
    assert printable or any(
        "reflecting shell is 0.751" in p and "0.8 mm" in p for p in report.problems
    )


def test_parts_pass_printability(built):
    design, layout, parts, collision = built
    assert collision.collision_free and collision.cells > 0 and collision.unproved_cells == 0
    assert 0.0 < collision.proved_clearance_mm <= collision.min_clearance_mm
    assert collision.min_clearance_mm <= layout.params.clearance_mm + 1e-9
    for name in ("reflector", "body"):
        solid = getattr(parts, name)
        report = check_printability(name, solid, to_trimesh(solid), layout, COARSE)
        assert report.ok, report.problems
        assert report.manifold and report.watertight and report.winding_consistent
        assert report.volume_mm3 > 0 and report.inside_envelope
        assert report.thinnest_wall_mm >= design.mechanics.min_wall_mm
        assert report.mesh_wall_mm >= design.mechanics.min_wall_mm - 2 * COARSE


def _box(size, at):
    import manifold3d as mf

    return mf.Manifold.cube(size).translate(at)


@pytest.mark.parametrize("ledge_mm", [0.004, 0.3])
def test_a_tessellations_step_is_no_wall_but_a_thin_plate_is(ledge_mm):
    """A block with a ledge 0.3 mm wide on its top: the ledge's side face, ``ledge_mm`` tall,
    casts its ray along the ledge (0.3 mm to its far side). A 0.004 mm step is a facet of the
    tessellation (below the chord tolerance) and measures no wall; a 0.3 mm tall ledge is a
    real 0.3 mm wall, measured whatever the facet limit, and so is a 0.5 mm plate."""
    block = _box((4.0, 4.0, 4.0), (0.0, 0.0, 0.0)) + _box((0.3, 4.0, ledge_mm), (0.0, 0.0, 4.0))
    unfiltered, _ = mesh_wall_thickness(block)
    filtered, _ = mesh_wall_thickness(block, facet_mm=0.01)
    assert unfiltered == pytest.approx(0.3, abs=1e-5)  # the step's ray along the ledge
    if ledge_mm < 0.01:
        assert filtered == math.inf  # every wall of the block is beyond the 3 mm search
    else:
        assert filtered == pytest.approx(0.3, abs=1e-5)
    plate = _box((4.0, 4.0, 0.5), (0.0, 0.0, 0.0))
    assert mesh_wall_thickness(plate, facet_mm=0.01)[0] == pytest.approx(0.5, abs=1e-5)
