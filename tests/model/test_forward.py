"""The composed forward model: shapes, symmetry, and the independent direct formulation."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from reflector_opt.design import Reflector, SensorPlacement
from reflector_opt.model._forward import respond, voltages
from reflector_opt.model._reference import direct_response
from reflector_opt.util._errors import CollisionError

angle = st.floats(-15, 15, allow_nan=False)


def test_shapes_follow_the_poses(design):
    pitch, roll = design.workspace.grid(1.0)
    r = respond(design, pitch, roll)
    assert r.volts.shape == r.distance_mm.shape == r.coupling.shape == (31, 31, 2)
    assert voltages(design, 3.0, -2.0).shape == (2,)
    assert voltages(design, np.zeros((4, 5)), 0.0).shape == (4, 5, 2)


def test_every_pose_layout_gives_the_same_values(design):
    """Grid, flat, scalar and three-dimensional pose arrays run the same per-pose model."""
    pitch, roll = design.workspace.grid(3.0)  # (11, 1) and (1, 11)
    grid = respond(design, pitch, roll)
    flat_pitch, flat_roll = (a.ravel() for a in np.broadcast_arrays(pitch, roll))
    flat = respond(design, flat_pitch, flat_roll)
    cube = respond(design, flat_pitch[:120].reshape(2, 3, 20), flat_roll[:120].reshape(2, 3, 20))
    for name in ("distance_mm", "axial_distance_mm", "coupling", "volts"):
        assert_allclose(getattr(flat, name), getattr(grid, name).reshape(-1, 2), rtol=1e-13)
        # 120 of the poses: computed at every pose, not interpolated (within 1e-4)
        assert_allclose(getattr(cube, name).reshape(-1, 2), getattr(flat, name)[:120], rtol=1e-4)
    single = respond(design, pitch[4, 0], roll[0, 7])
    assert single.volts.shape == (2,)
    assert_allclose(single.volts, grid.volts[4, 7], rtol=1e-4)


def test_matches_the_direct_vector_formulation(design):
    pitch, roll = design.workspace.grid(0.5)
    fast = respond(design, pitch, roll)
    distance, coupling, volts = direct_response(design, pitch, roll)
    assert_allclose(fast.distance_mm, distance, rtol=1e-13)
    # the coupling of many poses comes from a Chebyshev interpolant (docs/model.md §7)
    assert_allclose(fast.coupling, coupling, rtol=1e-4)
    assert_allclose(fast.volts, volts, atol=2e-4)


def test_matches_direct_formulation_for_a_skewed_design(design):
    skewed = design.replace(
        reflector=Reflector(radius_mm=8.5, centre_mm=(0.4, -0.3, -1.2), inner_radius_mm=7.2),
        sensors=(
            SensorPlacement("A", "NJL5901R-2", (9.6, 1.0, 0.4), (-1, -0.1, -0.05), (0, 1, 1)),
            SensorPlacement("B", "QRE1113", (-2.0, 9.7, -0.3), (0.2, -1, 0.03), (1, 0, 0)),
        ),
    )
    rng = np.random.default_rng(1)
    pitch, roll = rng.uniform(-15, 15, (2, 500))
    assert_allclose(
        voltages(skewed, pitch, roll), direct_response(skewed, pitch, roll)[2], atol=2e-4
    )


@settings(max_examples=30, deadline=None)
@given(angle=angle, other=angle)
def test_symmetric_design_gives_symmetric_responses(design, angle, other):
    """The default design is symmetric: S1 sees pitch as S2 sees −roll, and S1 is blind to
    the sign of roll (mirror y → −y)."""
    v = voltages(design, [angle, 0.0], [0.0, -angle])
    assert_allclose(v[0, 0], v[1, 1], atol=1e-12)
    v = voltages(design, angle, [other, -other])
    assert_allclose(v[0, 0], v[1, 0], atol=1e-12)


def test_voltage_falls_as_the_reflector_approaches(design):
    """Over the usable range, nearer reflector → more light → lower voltage (paper Fig. 8)."""
    pitch = np.linspace(-15, 15, 61)
    r = respond(design, pitch, 0.0)
    order = np.argsort(r.distance_mm[:, 0])
    assert np.all(np.diff(r.volts[order, 0]) > 0)


def test_collision_is_an_error_not_a_voltage(design):
    from reflector_opt.util._errors import InputError

    bigger = Reflector(radius_mm=9.5, centre_mm=(0, 0, -1.5))
    grown = design.replace(reflector=bigger)  # still clear of the sensors within ±15°
    with pytest.raises(CollisionError, match="inside the reflector sphere"):
        voltages(grown, -40.0, 0.0)  # beyond the workspace the sphere reaches S1
    with pytest.raises(InputError, match="S1, S2 would lie inside the reflector sphere"):
        design.replace(reflector=Reflector(radius_mm=9.9, centre_mm=(0, 0, -1.5)))
