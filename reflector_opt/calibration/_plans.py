"""Calibration plans: the poses a rig visits to calibrate one unit.

Four patterns over the workspace box [pitch_lo, pitch_hi] × [roll_lo, roll_hi]:

* ``raster`` — the paper's protocol (Osman et al. 2024, §4.1): every pose of the grid at the
  workspace step (0.1° gives 301 × 301 = 90,601 poses), visited row by row;
* ``grid`` — a coarse n × n grid including the corners, visited row by row (boustrophedon);
* ``sobol`` — scrambled Sobol points (:class:`scipy.stats.qmc.Sobol`, seeded), visited in a
  nearest-neighbour order;
* ``spiral`` — points on an Archimedean spiral from the centre, stretched to the box's
  corners (square-to-disc mapping inverted), visited in order.

Every plan is an array of shape (n, 2) of pitch and roll in visiting order, degrees;
:func:`path_length_deg` gives the motion it needs.
"""

import math

import numpy as np
from scipy.stats import qmc

from reflector_opt.util._errors import InputError

#: Plan patterns, in the order the planner reports them.
PATTERNS = ("raster", "grid", "sobol", "spiral")


def _serpentine(pitch, roll):
    """Grid poses row by row, every other row reversed: shape (len(pitch)·len(roll), 2)."""
    rows = [
        np.column_stack([np.full(len(roll), p), roll if i % 2 == 0 else roll[::-1]])
        for i, p in enumerate(pitch)
    ]
    return np.concatenate(rows)


def _nearest_neighbour_order(points):
    """Greedy tour from the first point to the nearest unvisited one (the lowest index among
    equals), O(n²): each step one pass over the squared distances, the visited ones masked."""
    n = len(points)
    pitch, roll = points[:, 0], points[:, 1]
    d_pitch, d_roll, distance = np.empty(n), np.empty(n), np.empty(n)
    visited = np.zeros(n, dtype=bool)
    order = np.empty(n, dtype=int)
    order[0], visited[0] = 0, True
    for k in range(1, n):
        last = points[order[k - 1]]
        np.subtract(pitch, last[0], out=d_pitch)
        np.subtract(roll, last[1], out=d_roll)
        np.multiply(d_pitch, d_pitch, out=distance)
        distance += d_roll * d_roll
        distance[visited] = np.inf
        order[k] = j = int(np.argmin(distance))
        visited[j] = True
    return points[order]


def _spiral(n):
    """``n`` points of an Archimedean spiral filling [-1, 1]², centre first."""
    t = np.sqrt((np.arange(n) + 0.5) / n)  # equal area per point
    turns = max(1.0, math.sqrt(n) / 2.0)
    angle = 2.0 * np.pi * turns * t
    u, v = t * np.cos(angle), t * np.sin(angle)
    # disc -> square (the inverse of the elliptical square-to-disc map), so corners are reached
    x = 0.5 * np.sqrt(np.maximum(2 + u**2 - v**2 + 2 * np.sqrt(2) * u, 0)) - 0.5 * np.sqrt(
        np.maximum(2 + u**2 - v**2 - 2 * np.sqrt(2) * u, 0)
    )
    y = 0.5 * np.sqrt(np.maximum(2 - u**2 + v**2 + 2 * np.sqrt(2) * v, 0)) - 0.5 * np.sqrt(
        np.maximum(2 - u**2 + v**2 - 2 * np.sqrt(2) * v, 0)
    )
    return np.clip(np.column_stack([x, y]), -1.0, 1.0)


def make_plan(workspace, pattern, n_poses=None, seed=0):
    """The poses of a calibration plan, in visiting order.

    Parameters
    ----------
    workspace : reflector_opt.design._components.Workspace
    pattern : {"raster", "grid", "sobol", "spiral"}
    n_poses : int, optional
        Number of poses; ``grid`` uses the nearest square (at least 4), ``raster`` ignores it
        (its size is set by the workspace step). Required except for ``raster``.
    seed : int
        Scrambling seed of ``sobol``.

    Returns
    -------
    numpy.ndarray
        Shape (n, 2): pitch, roll, degrees.
    """
    lo, hi = workspace.bounds()
    if pattern == "raster":
        pitch, roll = workspace.axes(workspace.step_deg)
        return _serpentine(pitch, roll)
    if pattern not in PATTERNS:
        raise InputError(f"pattern: expected one of {', '.join(PATTERNS)}, got {pattern!r}")
    if n_poses is None or isinstance(n_poses, bool) or int(n_poses) != n_poses or n_poses < 4:
        raise InputError(f"n_poses: must be a whole number of at least 4, got {n_poses}")
    n = int(n_poses)
    if pattern == "grid":
        side = max(2, round(math.sqrt(n)))
        return _serpentine(np.linspace(lo[0], hi[0], side), np.linspace(lo[1], hi[1], side))
    if pattern == "sobol":
        sampler = qmc.Sobol(2, scramble=True, seed=seed)
        unit = sampler.random_base2(math.ceil(math.log2(n)))[:n]
        return _nearest_neighbour_order(lo + (hi - lo) * unit)
    return lo + (hi - lo) * 0.5 * (_spiral(n) + 1.0)


def path_length_deg(plan):
    """Length of the path through a plan's poses in order, degrees (Euclidean in pitch, roll).

    Parameters
    ----------
    plan : array_like
        Shape (n, 2), degrees.

    Returns
    -------
    float
    """
    steps = np.diff(np.asarray(plan, dtype=float), axis=0)
    return float(np.sum(np.hypot(steps[:, 0], steps[:, 1])))
