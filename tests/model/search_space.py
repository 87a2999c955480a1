"""Random designs of the optimiser's whole search space, for every part of the sensor catalogue.

A design is drawn as the optimiser draws a candidate: every variable of
``Problem(sensor=part.model).search_bounds`` uniform between its bounds. Each design is
tested at two poses (a workspace corner, taken in turn, and a pose uniform over the
workspace) and keeps the sensor–pose pairs whose Eq 3 distance lies in the sensor's usable
range: the optimiser goes nowhere else. A design with no such pair is redrawn.

The designs fall in two regimes (docs/model.md §8): those whose whole distance window over
the workspace is in range — the designs that can meet the optimiser's distance-window
constraint — and the others, which leave the range or come near the sphere at some pose.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from reflector_opt.model._catalogue import shipped_catalogue
from reflector_opt.model._geometry import rotate_centre, sensor_distance, unit
from reflector_opt.optimiser._problem import Problem
from reflector_opt.util._errors import InputError

#: Designs per catalogue part (9 parts: 225 designs).
DESIGNS_PER_PART = 25
#: Grid step of the distance-window check, degrees (as ``Design``'s check).
WINDOW_STEP_DEG = 0.5


@dataclass(frozen=True)
class SampledDesign:
    """One random design and the sensor–pose pairs where it is in range.

    Attributes
    ----------
    part : str
        Catalogue part of both sensors.
    design : reflector_opt.design._design.Design
    poses : numpy.ndarray
        Shape (n, 2): pitch and roll of each kept pair, degrees.
    sensors : numpy.ndarray
        Shape (n,): sensor index of each kept pair.
    window_in_range : bool
        Every sensor within its usable range at every pose of a 0.5° workspace grid.
    """

    part: str
    design: object
    poses: np.ndarray
    sensors: np.ndarray
    window_in_range: bool


def _draw(problem, rng):
    bounds = problem.search_bounds
    while True:
        values = {k: rng.uniform(lo, hi) if hi > lo else lo for k, (lo, hi) in bounds.items()}
        try:
            return problem.design(values, checked=False)
        except InputError:
            continue


def _distances(design, pitch, roll):
    return sensor_distance(
        design.positions_mm,
        design.reflector.centre_mm,
        design.reflector.radius_mm,
        pitch,
        roll,
        on_collision="nan",
    )


def _in_range(design, distance):
    lo, hi = np.array([m.range_mm for m in design.models]).T
    return np.isfinite(distance) & (distance >= lo) & (distance <= hi)


def workspace_distances(design):
    """Eq 3 distance of every sensor over a 0.5° workspace grid, mm (NaN: inside the sphere)."""
    pitch, roll = design.workspace.grid(WINDOW_STEP_DEG)
    return _distances(design, pitch, roll)


def _window_in_range(design):
    return bool(np.all(_in_range(design, workspace_distances(design))))


def _sample(part, index, rng):
    problem = Problem(sensor=part.model)
    (p_lo, p_hi), (r_lo, r_hi) = problem.workspace.pitch_deg, problem.workspace.roll_deg
    corners = [(p_hi, r_hi), (p_lo, r_lo), (p_hi, r_lo), (p_lo, r_hi)]
    while True:
        design = _draw(problem, rng)
        poses = np.array([corners[index % 4], (rng.uniform(p_lo, p_hi), rng.uniform(r_lo, r_hi))])
        kept = _in_range(design, _distances(design, poses[:, 0], poses[:, 1]))
        pose_index, sensor_index = np.nonzero(kept)
        if pose_index.size:
            return SampledDesign(
                part.name, design, poses[pose_index], sensor_index, _window_in_range(design)
            )


@functools.cache
def sampled_designs(per_part=DESIGNS_PER_PART, seed=30):
    """``per_part`` random designs of every catalogue part's search space, cached.

    Parameters
    ----------
    per_part : int
    seed : int

    Returns
    -------
    tuple of SampledDesign
    """
    rng = np.random.default_rng(seed)
    return tuple(_sample(part, i, rng) for part in shipped_catalogue() for i in range(per_part))


def frame_centres(design, pitch_deg, roll_deg):
    """Sphere centre in every sensor's frame (a, u, w), from explicit vectors, mm.

    Returns
    -------
    numpy.ndarray
        Shape ``P + (n_sensors, 3)``.
    """
    s1 = rotate_centre(design.reflector.centre_mm, pitch_deg, roll_deg)
    out = []
    for placement in design.sensors:
        a = unit(np.asarray(placement.axis, dtype=float))
        u = placement.in_plane_detector_direction
        p = np.asarray(placement.position_mm, dtype=float) - s1
        out.append(-np.stack([p @ a, p @ u, p @ np.cross(a, u)], axis=-1))
    return np.stack(out, axis=-2)
