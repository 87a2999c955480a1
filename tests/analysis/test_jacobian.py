"""The finite-difference Jacobian: stencil layout, against the analytic Eq 3 derivative and
a Richardson extrapolation of the voltages."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt.analysis._jacobian import stencil_poses, values_and_jacobian, voltage_jacobian
from reflector_opt.design import default_design
from reflector_opt.model._geometry import rotation_x, rotation_y, sensor_distance


def test_stencil_layout():
    pitch, roll = stencil_poses(np.array([[1.0], [2.0]]), np.array([[5.0, 6.0, 7.0]]), 0.5)
    assert pitch.shape == roll.shape == (5, 2, 3)
    assert_allclose(pitch[:, 0, 0], [1.0, 1.5, 0.5, 1.0, 1.0])
    assert_allclose(roll[:, 0, 0], [5.0, 5.0, 5.0, 5.5, 4.5])


def _distance_jacobian_analytic(design, pitch, roll):
    """∂d/∂(γ, α) of Eq 3 by the chain rule, per degree (independent of the metrics code)."""
    s0 = np.asarray(design.reflector.centre_mm)
    g, a = np.deg2rad(pitch), np.deg2rad(roll)
    d_ry = np.array([[-np.sin(g), 0, np.cos(g)], [0, 0, 0], [-np.cos(g), 0, -np.sin(g)]])
    d_rx = np.array([[0, 0, 0], [0, -np.sin(a), -np.cos(a)], [0, np.cos(a), -np.sin(a)]])
    rx, ry = rotation_x(roll), rotation_y(pitch)
    s1 = rx @ ry @ s0
    ds_dg = rx @ d_ry @ s0
    ds_da = d_rx @ ry @ s0
    out = []
    for f in design.positions_mm:
        p = f - s1
        u = p / np.linalg.norm(p)
        out.append([-u @ ds_dg, -u @ ds_da])
    return np.array(out) * np.pi / 180.0


@pytest.mark.parametrize("pose", [(0.0, 0.0), (12.0, -7.5), (-15.0, 15.0)])
def test_jacobian_of_eq3_matches_the_analytic_derivative(pose):
    design = default_design()
    reflector = design.reflector

    def distance(p, r):
        return sensor_distance(design.positions_mm, reflector.centre_mm, reflector.radius_mm, p, r)

    _, jac = values_and_jacobian(distance, *pose)
    exact = _distance_jacobian_analytic(design, *pose)
    # mm/deg: the truncation error h²/6·|d'''| is ~1e-9 here; rounding ~1e-13
    assert_allclose(jac, exact, rtol=0, atol=1e-9)
    assert np.abs(exact).max() > 1e-3  # the test is not comparing zeros


def test_voltage_jacobian_agrees_with_richardson_extrapolation():
    design = default_design()
    pitch = np.array([[-15.0], [-3.3], [9.0], [15.0]])
    roll = np.array([[-15.0, 0.0, 7.7, 15.0]])
    jac = voltage_jacobian(design, pitch, roll)
    coarse = voltage_jacobian(design, pitch, roll, step_deg=0.08)
    fine = voltage_jacobian(design, pitch, roll, step_deg=0.04)
    richardson = (4.0 * fine - coarse) / 3.0  # error O(h⁴)
    scale = np.abs(richardson).max()
    assert scale > 1e-3
    assert np.abs(jac - richardson).max() < 1e-5 * scale
