"""Chebyshev interpolation of the coupling over the poses."""

import numpy as np
from numpy.testing import assert_allclose

from reflector_opt.model import _forward as forward
from reflector_opt.model._interpolation import PoseBox, fit_coefficients, interpolate


def test_reproduces_a_polynomial_exactly():
    box = PoseBox((-15, 15), (-10, 5), nodes=5)
    pitch, roll = box.points()

    def poly(p, r):
        return np.stack([1 + 0.1 * p - 0.02 * p * r**2, (r / 10) ** 4 - p**3 / 1e3], axis=-1)

    coef = fit_coefficients(box, poly(pitch, roll))
    rng = np.random.default_rng(0)
    p, r = rng.uniform(-15, 15, 50), rng.uniform(-10, 5, 50)
    assert_allclose(interpolate(box, coef, p, r), poly(p, r), atol=1e-12)
    grid_p, grid_r = np.linspace(-15, 15, 7)[:, None], np.linspace(-10, 5, 4)[None, :]
    assert_allclose(interpolate(box, coef, grid_p, grid_r), poly(grid_p, grid_r), atol=1e-12)


def test_a_stack_of_grids_matches_the_same_poses_scattered():
    """The stencil of a grid (pitch constant along rows, roll along columns, per layer) takes
    the grid path; it must agree with the scattered path on the same poses, and a stack that
    is not of grids (one pose moved) must still be right."""
    box = PoseBox((-15, 15), (-10, 5), nodes=6)
    rng = np.random.default_rng(1)
    coef = fit_coefficients(box, rng.standard_normal((6, 6, 3)))
    shift = np.array([0.0, 0.5, -0.5, 0.0, 0.0])[:, None, None]
    pitch = np.linspace(-14, 14, 9)[None, :, None] + shift + np.zeros((1, 1, 4))
    roll = np.linspace(-9, 4, 4)[None, None, :] + shift[::-1] + np.zeros((1, 9, 1))
    scattered = interpolate(box, coef, pitch.ravel(), roll.ravel()).reshape(5, 9, 4, 3)
    assert_allclose(interpolate(box, coef, pitch, roll), scattered, rtol=1e-13, atol=1e-13)
    pitch[2, 3, 1] += 0.3
    scattered = interpolate(box, coef, pitch.ravel(), roll.ravel()).reshape(5, 9, 4, 3)
    assert_allclose(interpolate(box, coef, pitch, roll), scattered, rtol=1e-13, atol=1e-13)


def test_coupling_interpolant_is_within_5e_5_of_the_coupling(design):
    """±15° with 7 × 7 Chebyshev points: the error is far below the model's own (0.2 %)."""
    rng = np.random.default_rng(2)
    pitch, roll = rng.uniform(-15, 15, (2, 100))
    direct = forward.respond(design, pitch, roll).coupling  # few poses: computed directly
    box = PoseBox((-15, 15), (-15, 15))
    assert box.nodes == 7
    node_pitch, node_roll = box.points()
    centres = np.moveaxis(forward._geometry(design, node_pitch, node_roll)[2:], 0, -1)
    coef = fit_coefficients(box, forward._coupling(design, centres))
    assert_allclose(interpolate(box, coef, pitch, roll), direct, rtol=5e-5)
