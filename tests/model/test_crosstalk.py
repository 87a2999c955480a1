"""Crosstalk between the sensors of a unit: the fast model by hand and against the exact one."""

import dataclasses

import numpy as np
import pytest

from reflector_opt import default_design
from reflector_opt.design._components import Reflector, SensorPlacement
from reflector_opt.model import _crosstalk as crosstalk
from reflector_opt.model._crosstalk import (
    cross_couplings,
    cross_surface_couplings,
    crosstalk_fraction,
)
from reflector_opt.model._exact import (
    exact_cross_coupling,
    exact_design_coupling,
    exact_design_cross_coupling,
)
from reflector_opt.model._forward import respond
from reflector_opt.model._geometry import rotate_centre
from reflector_opt.model._sensors import NJL5901R_2
from reflector_opt.util._errors import InputError

#: Orders of the exact reference here: within 4e-4 of its default orders on these designs.
ORDERS = {"source_order": 4, "detector_order": (2, 6), "sphere_order": (48, 48)}
#: The workspace's corners and centre, (pitch, roll) in degrees.
POSES = np.array([(0.0, 0.0), (-15.0, -15.0), (-15.0, 15.0), (15.0, -15.0), (15.0, 15.0)]).T


def _ring(angles_deg, detector_directions):
    """The default unit with its sensors at these angles round the 10 mm ring, looking in."""
    sensors = []
    for i, (angle, direction) in enumerate(zip(angles_deg, detector_directions, strict=True)):
        c, s = np.cos(np.deg2rad(angle)), np.sin(np.deg2rad(angle))
        sensors.append(
            SensorPlacement(
                f"S{i + 1}", "NJL5901R-2", (10 * c, 10 * s, 0.0), (-c, -s, 0.0), direction
            )
        )
    return default_design().replace(sensors=tuple(sensors))


# --- (a) by hand --------------------------------------------------------------------------


#: A point-like part with a narrow beam: its spot and its ray tube are single rays.
POINT = dataclasses.replace(
    NJL5901R_2,
    name="point-like",
    emitter_detector_mm=1e-4,
    source_radius_mm=1e-4,
    detector_area_mm2=1e-6,
    divergence_deg=0.25,
)
RADIUS, RING, HALF_ANGLE = 9.0, 10.0, np.deg2rad(10.0)


@pytest.fixture(scope="module")
def mirror_pair():
    """Two point-like sensors symmetric about the plane y = 0, both aimed at P = (R, 0, 0)
    of a sphere centred at O (so every pose is the same geometry)."""
    f1 = RING * np.array([np.cos(HALF_ANGLE), np.sin(HALF_ANGLE), 0.0])
    f2 = f1 * [1.0, -1.0, 1.0]
    point = np.array([RADIUS, 0.0, 0.0])
    sensors = tuple(
        SensorPlacement(name, "point-like", tuple(f), tuple(point - f))
        for name, f in (("S1", f1), ("S2", f2))
    )
    reflector = Reflector(radius_mm=RADIUS, centre_mm=(0.0, 0.0, 0.0))
    return default_design().replace(
        reflector=reflector, sensors=sensors, sensor_models={"point-like": POINT}
    )


def _by_hand():
    """Mirror and Lambertian couplings from S1 to S2 of ``mirror_pair``, by hand.

    By symmetry the specular point is P = (R, 0, 0) with normal x; each path is
    s = sqrt(D² + R² − 2DR cos φ) long and meets the normal at cos i = (D cos φ − R)/s. The
    ray leaves along S1's axis (slope 0: I = q(0) = 1/(πT²)) and arrives along S2's
    (cos ψ = 1 against S2's own axis). Mirror: the ray tube,
    S·I/[(2s + 2s²/(R cos i))(2s + 2s² cos i/R)]. Lambertian: the whole beam lands at P,
    which sends cos i/π per steradian towards S2: S cos i/(π s²).
    """
    s = np.sqrt(RING**2 + RADIUS**2 - 2 * RING * RADIUS * np.cos(HALF_ANGLE))
    cos_i = (RING * np.cos(HALF_ANGLE) - RADIUS) / s
    area, slope = POINT.detector_area_mm2, np.tan(np.deg2rad(POINT.divergence_deg))
    tube = (2 * s + 2 * s * s / (RADIUS * cos_i)) * (2 * s + 2 * s * s * cos_i / RADIUS)
    return area / (np.pi * slope**2) / tube, area * cos_i / (np.pi * s * s)


def test_fast_model_matches_the_hand_computed_pair(mirror_pair):
    mirror, lambertian = _by_hand()
    fast = cross_surface_couplings(mirror_pair, [0.0, 10.0], [0.0, -5.0])
    for k, j in ((1, 0), (0, 1)):
        assert fast.mirror[:, k, j] == pytest.approx(mirror, rel=1e-3)
        assert fast.lambertian[:, k, j] == pytest.approx(lambertian, rel=1e-3)
    assert np.all(np.diagonal(fast.mirror, axis1=-2, axis2=-1) == 0.0)


def test_exact_reference_matches_the_hand_computed_pair(mirror_pair):
    mirror, lambertian = _by_hand()
    (s1, s2), offsets = mirror_pair.sensors, mirror_pair.detector_offsets_mm
    exact = exact_cross_coupling(
        *(s1.position_mm, s1.axis, offsets[0]),
        *(s2.position_mm, s2.axis, offsets[1]),
        (0.0, 0.0, 0.0),
        RADIUS,
        POINT,
        POINT,
        **ORDERS,
    )
    assert exact.mirror == pytest.approx(mirror, rel=1e-3)
    assert exact.lambertian == pytest.approx(lambertian, rel=1e-3)


# --- (b) against the exact reference where crosstalk matters ----------------------------------


@pytest.fixture(scope="module")
def three():
    """Three sensors 20° apart round the ring (neighbours see 1e-3 to 0.2 of their own light,
    the outer pair 1e-10 to 2e-3), their LED-to-detector directions up, along the ring and
    down, so that no two pairs are alike; the exact couplings at the poses."""
    along = (-np.sin(np.deg2rad(20.0)), np.cos(np.deg2rad(20.0)), 0.0)
    design = _ring((0.0, 20.0, 40.0), [(0, 0, 1), along, (0, 0, -1)])
    return design, exact_design_cross_coupling(design, *POSES, **ORDERS)


def _disagreements(fast, exact):
    """Pairs where the fast couplings miss the exact ones by more than 3 % of the exact value
    plus 2e-4 of the detector's own coupling, for either share; as (share, pose, k, j)."""
    found = []
    for share in ("mirror", "lambertian"):
        e, f = getattr(exact, share), getattr(fast, share)
        own = np.diagonal(e, axis1=-2, axis2=-1)[..., :, None]
        off = ~np.eye(e.shape[-1], dtype=bool)
        bad = (np.abs(f - e) > 0.03 * e + 2e-4 * own) & off
        found += [(share, *index) for index in zip(*np.nonzero(bad), strict=True)]
    return found


def test_fast_model_agrees_with_the_exact_reference(three):
    """Measured here: both shares within 3 % where the crosstalk fraction is above 1e-3
    (benchmarks/crosstalk_agreement.py: mirror 1.5 %, Lambertian 7 % from 1e-3 to 1e-2 over
    more designs), tails below 2e-4 of the own coupling."""
    design, exact = three
    fast = cross_surface_couplings(design, *POSES)
    assert _disagreements(fast, exact) == []
    sizable = exact.lambertian / np.diagonal(exact.lambertian, axis1=-2, axis2=-1)[..., :, None]
    assert np.count_nonzero(sizable > 0.01) >= 10  # the check is not on negligible crosstalk


def test_the_agreement_check_fails_with_the_emitters_axis_for_the_detectors(three, monkeypatch):
    """A fast model that takes cos ψ against the emitter's axis, not the detector's own."""
    design, exact = three
    for name in ("_mirror_share", "_lambertian_share"):
        share = getattr(crosstalk, name)

        def wrong(emitter, detector, *args, share=share):
            return share(emitter, detector._replace(axis=emitter.frame[0]), *args)

        monkeypatch.setattr(crosstalk, name, wrong)
    assert len(_disagreements(cross_surface_couplings(design, *POSES), exact)) > 10


def test_the_agreement_check_fails_for_the_transposed_matrix(three):
    """Emitter and detector swapped: the pairs differ (detector directions), so it shows."""
    design, exact = three
    fast = cross_surface_couplings(design, *POSES)
    swapped = type(fast)(np.swapaxes(fast.mirror, -1, -2), np.swapaxes(fast.lambertian, -1, -2))
    assert len(_disagreements(swapped, exact)) > 10


def test_surface_and_fraction_follow_the_exact_reference(three):
    """η_kj with the design's ρ and f, and over the forward model's own coupling, against the
    exact cross over the exact own coupling: within 3 % where the fraction is above 1 %."""
    design, exact = three
    reflector = design.reflector
    exact_total = exact.total(reflector.reflectance, reflector.specular_fraction)
    own = np.diagonal(exact_total, axis1=-2, axis2=-1)[..., :, None]
    expected = np.where(np.eye(3, dtype=bool), 0.0, exact_total / own)
    fraction = crosstalk_fraction(design, *POSES)
    sizable = expected > 0.01
    assert np.count_nonzero(sizable) >= 10
    assert fraction[sizable] == pytest.approx(expected[sizable], rel=0.03)
    assert np.abs(fraction - expected).max() < 2e-3
    fast = cross_surface_couplings(design, *POSES)
    total = fast.total(reflector.reflectance, reflector.specular_fraction)
    assert np.array_equal(cross_couplings(design, *POSES), total)


def test_exact_diagonal_is_the_own_coupling(three):
    design, exact = three
    own = exact_design_coupling(design, *POSES, **ORDERS)
    assert np.array_equal(np.diagonal(exact.mirror, axis1=-2, axis2=-1), own.mirror)
    assert np.array_equal(np.diagonal(exact.lambertian, axis1=-2, axis2=-1), own.lambertian)


# --- (c) the default design -----------------------------------------------------------------


def test_default_design_has_no_crosstalk_by_the_reflector(design):
    """Zero, exactly, at the workspace corners, in the exact reference and the fast model.

    The sensors sit 90° apart round the ring. Each sees only the cap of the sphere within
    arccos(R/|f − c|) of the direction from the centre c to it (22°–31° over the workspace),
    and the two directions are 85°–93° apart (over a 0.5° grid the angle between them
    exceeds the two caps by 23° at least), so no point of the reflector is seen by both: no
    mirror path (its specular point would lie in both caps) and no diffuse path (a lit point
    the other detector sees) joins one sensor's LED to the other's detector.
    """
    pitch, roll = POSES[:, 1:]
    centres = rotate_centre(design.reflector.centre_mm, pitch, roll)
    f1, f2 = (design.positions_mm[k] - centres for k in (0, 1))
    lengths = [np.linalg.norm(f, axis=-1) for f in (f1, f2)]
    between = np.degrees(np.arccos(np.sum(f1 * f2, -1) / (lengths[0] * lengths[1])))
    caps = sum(np.degrees(np.arccos(design.reflector.radius_mm / n)) for n in lengths)
    assert np.all(between - caps > 20.0)
    exact = exact_design_cross_coupling(design, pitch, roll, source_order=3, sphere_order=(24, 24))
    off = ~np.eye(2, dtype=bool)
    assert np.all(exact.mirror[:, off] == 0.0) and np.all(exact.lambertian[:, off] == 0.0)
    assert np.all(exact.lambertian[:, ~off] > 0.0)
    assert np.all(crosstalk_fraction(design, pitch, roll) == 0.0)


# --- inputs and shapes ----------------------------------------------------------------------


def test_shapes_broadcast_and_the_diagonal_is_zero(three):
    design, _ = three
    fraction = crosstalk_fraction(design, np.zeros((2, 1)), np.zeros(3))
    assert fraction.shape == (2, 3, 3, 3)
    assert np.all(np.diagonal(fraction, axis1=-2, axis2=-1) == 0.0)
    own = respond(design, 0.0, 0.0).coupling
    assert fraction[0, 0, 1, 0] == pytest.approx(cross_couplings(design, 0.0, 0.0)[1, 0] / own[1])


def test_a_pose_that_is_not_finite_is_refused(three):
    design, _ = three
    with pytest.raises(InputError, match="roll_deg"):
        cross_couplings(design, 0.0, [0.0, np.nan])
