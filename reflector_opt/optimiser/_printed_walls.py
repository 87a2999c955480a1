"""The walls of the printed parts, judged by the CAD export's own rules.

``printed_wall_mm`` is the thinnest wall of :func:`reflector_opt.design._layout.plan_layout`,
the function the CAD export builds from (:func:`check_printed`, 0.2–0.5 s a design). It is too
costly for every candidate of the global search, which steers by cheap smooth constraints
(``wall_mm``, ``distance_margin_mm``, ``reflector_envelope_mm``, ``window_wall_mm``). Once a
polished design fails it, the walls that depend on the design (:data:`DESIGNED_WALLS`) become
constraints of the polish themselves: exact values at the design and their forward-difference
slopes (:func:`linearised_walls`), refreshed at each new point until the layout itself passes,
so that the optimum sits on the wall limit instead of behind an inflated proxy margin.
"""

import functools
from dataclasses import dataclass, replace

import numpy as np

from reflector_opt.design._layout import plan_layout
from reflector_opt.optimiser._constraints import Constraint
from reflector_opt.optimiser._variables import forward_steps, values_from_vector
from reflector_opt.util._errors import InputError

#: Name of the constraint on the walls of the printed parts.
PRINTED_WALL = "printed_wall_mm"

#: The printed walls (``"part: wall"``, see :func:`reflector_opt.design._layout.plan_layout`) that
#: depend on the design variables; the others are fixed by the CAD parameters and the
#: mechanics, and no design repairs them.
DESIGNED_WALLS = (
    "reflector: reflecting shell",
    "body: wall behind a sensor channel",
    "body: wall outside the swept space",
    "body: wall between a tendon hole and the swept space",
    "body: wall above a sensor window",
)

#: Forward-difference step of the walls' slopes, in units of each variable's range. The layout
#: takes its extremes on 0.1° angle grids and a 1° pose grid, and the wall behind a sensor
#: channel is a minimum over the swept keep-outs, so the walls change in small steps: a step
#: of 10⁻³ of the range saw those facets instead of the slope, and with a required distance
#: margin of 0.05 mm the repair it steered wandered to 0.1218° where 0.0874° is printable
#: (2 × 10⁻² of the range finds it; 10⁻² does not).
WALL_STEP = 2e-2

#: Walls thicker than the minimum by more than this (mm) are left out of the linear model:
#: far from their limit they cannot become active within one polish.
WALL_WATCH_MM = 0.25


def _walls(layout):
    walls = {f"reflector: {k}": float(v) for k, v in layout.reflector_walls_mm.items()}
    return walls | {f"body: {k}": float(v) for k, v in layout.body_walls_mm.items()}


def check_printed(problem, evaluation):
    """Add the walls of the printed parts to an evaluation, by the CAD export's rules.

    The layout of both parts (:func:`reflector_opt.design._layout.plan_layout`, the function the
    CAD export builds from) gives every designed wall; the thinnest becomes the
    constraint ``printed_wall_mm`` (≥ ``mechanics.min_wall_mm``), its ``detail`` naming
    the wall. A design the parts cannot be laid out for at all becomes invalid, with the
    layout's reason.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
        Its ``cad`` parameters and minimum wall.
    evaluation : reflector_opt.optimiser._evaluation.Evaluation
        A valid candidate, usually on the workspace grid.

    Returns
    -------
    reflector_opt.optimiser._evaluation.Evaluation
        With ``printed_walls_mm`` filled in (unchanged if ``evaluation`` is not valid).
    """
    if evaluation.error is not None or evaluation.design is None:
        return evaluation
    try:
        layout = plan_layout(evaluation.design, problem.cad)
    except InputError as exc:
        return replace(evaluation, error=f"printed parts: {exc}")
    walls = _walls(layout)
    thinnest = min(walls, key=walls.get)
    constraint = Constraint(
        PRINTED_WALL,
        walls[thinnest],
        float(problem.mechanics.min_wall_mm),
        False,
        "mm",
        1.0,
        detail=thinnest,
    )
    return replace(
        evaluation,
        constraints=(*evaluation.constraints, constraint),
        printed_walls_mm=walls,
    )


def designed_walls_mm(problem, values):
    """The :data:`DESIGNED_WALLS` of the design at ``values``, by the CAD export's layout.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
    values : mapping of str to float
        Every design variable.

    Returns
    -------
    numpy.ndarray or None
        Shape ``(len(DESIGNED_WALLS),)``, mm; None if the values make no design or the parts
        cannot be laid out for it.
    """
    try:
        walls = _walls(plan_layout(problem.design(values, checked=False), problem.cad))
    except InputError:
        return None
    return np.array([walls[name] for name in DESIGNED_WALLS])


@dataclass(frozen=True)
class LinearWalls:
    """The designed walls near a point, ``w(u) ≈ value + slope · (u − at)``.

    ``u`` are the free variables scaled to [0, 1] over their bounds (as in the polish).

    Attributes
    ----------
    at : numpy.ndarray, shape (n,)
        The point, scaled.
    value : numpy.ndarray, shape (k,)
        The walls there, mm (only those within :data:`WALL_WATCH_MM` of the limit).
    slope : numpy.ndarray, shape (k, n)
        Their forward-difference derivatives, mm per unit of scaled variable.
    names : tuple of str
        Which walls.
    limit : numpy.ndarray, shape (k,)
        Each wall's required thickness, mm (the minimum wall plus any extra demanded).
    """

    at: np.ndarray
    value: np.ndarray
    slope: np.ndarray
    names: tuple
    limit: np.ndarray

    def margins(self, u):
        """Linearised wall minus its limit at the scaled points ``u``, mm (≥ 0 when met)."""
        return self.value + self.slope @ (np.asarray(u, dtype=float) - self.at) - self.limit

    def unreachable(self):
        """The walls whose model stays below its limit over the whole box ``0 ≤ u ≤ 1``.

        A linear function's largest value over a box is at a corner:
        ``max w = value + Σ_k max(slope_k·(0 − at_k), slope_k·(1 − at_k))``. A wall that the
        design variables do not move (a zero slope: it is set by the CAD parameters and the
        envelope at this design, e.g. the dome's swept space at a tendon hole) is one.

        Returns
        -------
        tuple of str
        """
        reach = np.maximum(-self.slope * self.at, self.slope * (1.0 - self.at)).sum(axis=1)
        margin = self.value + reach - self.limit
        return tuple(n for n, m in zip(self.names, margin, strict=True) if m < 0)


def linearised_walls(problem, x, lower, upper, extra_mm=None, walls_mm=None, map_=map):
    """Exact designed walls at ``x`` and their slopes: a linear model for the polish.

    ``1 + n`` layouts (n free variables) by the export's own rules
    (:func:`designed_walls_mm`), forward differences of :data:`WALL_STEP` of each range; ``n``
    when the walls at ``x`` are given.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
    x : numpy.ndarray
        Free variables.
    lower, upper : numpy.ndarray
        Their bounds.
    extra_mm : mapping of str to float, optional
        Thickness demanded beyond ``mechanics.min_wall_mm`` for named walls (to make up for
        the linear model's error in a previous round).
    walls_mm : mapping of str to float, optional
        Every printed wall at ``x`` (:attr:`Evaluation.printed_walls_mm
        <reflector_opt.optimiser._evaluation.Evaluation.printed_walls_mm>` of
        :func:`check_printed` there), so that the layout at ``x`` is not computed again.
    map_ : callable, optional
        ``map_(function, items)``, ordered like the builtin ``map`` (e.g. a worker pool's
        ``map``): the forward-difference layouts are computed with it.

    Returns
    -------
    (LinearWalls or None, int)
        The model (None if the layout fails at ``x`` or no wall is near its limit) and the
        layouts it used.
    """
    names, fixed = problem.free_names, problem.fixed_values
    span = upper - lower
    u0 = (np.asarray(x, dtype=float) - lower) / span
    if walls_mm is None:
        base, layouts = designed_walls_mm(problem, values_from_vector(names, x, fixed)), 1
    else:
        base, layouts = np.array([walls_mm[name] for name in DESIGNED_WALLS]), 0
    if base is None:
        return None, layouts
    minimum = float(problem.mechanics.min_wall_mm)
    watched = np.flatnonzero(base < minimum + WALL_WATCH_MM)
    if watched.size == 0:
        return None, layouts
    steps, points = forward_steps(u0, WALL_STEP)
    moved = [values_from_vector(names, lower + uk * span, fixed) for uk in points]
    slope = np.zeros((watched.size, u0.size))
    for k, walls in enumerate(map_(functools.partial(designed_walls_mm, problem), moved)):
        if walls is None:
            return None, layouts + 1 + k
        slope[:, k] = (walls[watched] - base[watched]) / steps[k]
    chosen = tuple(DESIGNED_WALLS[i] for i in watched)
    extra = extra_mm or {}
    limit = np.array([minimum + extra.get(name, 0.0) for name in chosen])
    return LinearWalls(u0, base[watched], slope, chosen, limit), layouts + u0.size
