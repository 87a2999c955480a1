"""Chebyshev interpolation of a per-pose quantity over a box of pitch and roll.

The optical coupling is a smooth (analytic) function of the pose, so a tensor-product
Chebyshev interpolant through its values at n × n Chebyshev points of the box reproduces it
to far below the model's own accuracy: the forward model computes the radiometry at those
points only and evaluates the interpolant at every requested pose
(:func:`reflector_opt.model._forward.respond`). On a pitch × roll grid the interpolant is two
small matrix products. tests/model/test_interpolation.py measures the interpolation error.
"""

import functools
import math

import numpy as np
from numpy.polynomial import chebyshev

from reflector_opt.model import _kernel as kernel

#: Chebyshev points per axis for every 30° of the box's span (at least 5, at most 25); over
#: ±15° the interpolant is within 5e-5 of the coupling (tests/model/test_interpolation.py).
NODES_PER_30_DEG = 7


class PoseBox:
    """The box [pitch_lo, pitch_hi] × [roll_lo, roll_hi] and its Chebyshev points.

    Parameters
    ----------
    pitch_deg, roll_deg : (float, float)
        Bounds of the box, degrees (lower < upper).
    nodes : int, optional
        Points per axis (default from the wider span, :data:`NODES_PER_30_DEG`).
    """

    def __init__(self, pitch_deg, roll_deg, nodes=None):
        self.pitch_deg = tuple(float(v) for v in pitch_deg)
        self.roll_deg = tuple(float(v) for v in roll_deg)
        if nodes is None:
            span = max(np.ptp(self.pitch_deg), np.ptp(self.roll_deg))
            nodes = min(max(math.ceil(NODES_PER_30_DEG * span / 30.0), 5), 25)
        self.nodes = int(nodes)

    @classmethod
    def around(cls, pitch_deg, roll_deg):
        """The smallest box holding every pose, or None if it is flat in pitch or roll."""
        pitch_lo, pitch_hi = float(np.min(pitch_deg)), float(np.max(pitch_deg))
        roll_lo, roll_hi = float(np.min(roll_deg)), float(np.max(roll_deg))
        if not (pitch_hi > pitch_lo and roll_hi > roll_lo):
            return None
        return cls((pitch_lo, pitch_hi), (roll_lo, roll_hi))

    def _unit(self, values, bounds):
        lo, hi = bounds
        return (2.0 * np.asarray(values, dtype=float) - (lo + hi)) / (hi - lo)

    def points(self):
        """Pitch (n, 1) and roll (1, n) of the Chebyshev points (first kind), degrees."""
        x = chebyshev.chebpts1(self.nodes)

        def scale(bounds):
            lo, hi = bounds
            return 0.5 * (lo + hi) + 0.5 * (hi - lo) * x

        return scale(self.pitch_deg)[:, None], scale(self.roll_deg)[None, :]

    def vander(self, pitch_deg, roll_deg):
        """Chebyshev polynomials at the given pitches and rolls, shapes ``P + (n,)``."""
        n = self.nodes - 1
        return (
            chebyshev.chebvander(self._unit(pitch_deg, self.pitch_deg), n),
            chebyshev.chebvander(self._unit(roll_deg, self.roll_deg), n),
        )


@functools.cache
def _inverse_vander(n):
    """Inverse of the Chebyshev matrix at the n points of the first kind (not to be changed).

    There the polynomials are orthogonal: the inverse is the transpose times 2/n, with the
    first row halved.
    """
    inverse = (2.0 / n) * chebyshev.chebvander(chebyshev.chebpts1(n), n - 1).T
    inverse[0] *= 0.5
    return inverse


def fit_coefficients(box, values):
    """Coefficients of the interpolant through values at the box's Chebyshev points.

    Parameters
    ----------
    box : PoseBox
    values : numpy.ndarray, shape (n, n, ...)
        Values at :meth:`PoseBox.points` (pitch along the first axis, roll the second).

    Returns
    -------
    numpy.ndarray
        Coefficients c_jk, shape of ``values``.
    """
    n = box.nodes
    inverse = _inverse_vander(n)
    flat = np.ascontiguousarray(np.asarray(values, dtype=float).reshape(n, n, -1))
    out = np.empty_like(flat)
    kernel.tensor_series_grid(inverse, flat, inverse, out)
    return out.reshape(np.shape(values))


def _grid_axes(pitch, roll, shape):
    """The pitch and roll axes if the poses are grids (pitch varying along the last axis but
    one only, roll along the last only), shapes ``shape[:-1]`` and ``shape[:-2] + shape[-1:]``;
    else None."""
    if len(shape) < 2:
        return None
    if pitch.ndim == 2 and roll.ndim == 2 and pitch.shape[1] == 1 and roll.shape[0] == 1:
        return pitch[:, 0], roll[0]  # a grid given as a column and a row: nothing to compare
    pitch, roll = np.broadcast_to(pitch, shape), np.broadcast_to(roll, shape)
    if np.all(pitch == pitch[..., :1]) and np.all(roll == roll[..., :1, :]):
        return pitch[..., 0], roll[..., 0, :]
    return None


def interpolate(box, coefficients, pitch_deg, roll_deg):
    """The interpolant at arbitrary poses.

    Parameters
    ----------
    box : PoseBox
    coefficients : numpy.ndarray, shape (n, n) + T
        From :func:`fit_coefficients`.
    pitch_deg, roll_deg : numpy.ndarray
        Poses, degrees, broadcast to shape P; a pitch column and a roll row (a grid), or a
        stack of grids (pitch constant along the last axis and roll along the one before,
        as on the stencil of a grid), take two matrix products per grid.

    Returns
    -------
    numpy.ndarray
        Shape ``P + T``.
    """
    pitch, roll = np.asarray(pitch_deg, dtype=float), np.asarray(roll_deg, dtype=float)
    tail = coefficients.shape[2:]
    flat = np.ascontiguousarray(coefficients.reshape(box.nodes, box.nodes, -1))
    shape = np.broadcast_shapes(pitch.shape, roll.shape)
    grids = _grid_axes(pitch, roll, shape)
    if grids is not None:
        vp, vr = box.vander(*grids)
        out = np.empty((*shape, flat.shape[-1]))
        for i in np.ndindex(shape[:-2]):
            kernel.tensor_series_grid(vp[i], flat, vr[i], out[i])
        return out.reshape(shape + tail)
    vp, vr = box.vander(np.broadcast_to(pitch, shape).ravel(), np.broadcast_to(roll, shape).ravel())
    out = np.empty((len(vp), flat.shape[-1]))
    kernel.tensor_series(vp, flat, vr, out)
    return out.reshape(shape + tail)
