"""Verification of a polished design on the workspace grid and of its printed walls, with repair.

The search and the polish judge a design on coarse pose grids; the design returned must pass
on the workspace grid (0.1°) and its printed parts must pass the CAD export's own wall check
(:func:`~reflector_opt.optimiser._printed_walls.check_printed`). If a per-pose constraint fails
there (it was met only on the coarser grid), it is tightened and the polish is repeated, up to
:data:`REPAIR_ROUNDS` times.

A printed wall that is too thin makes the designed walls linear constraints of the polish, exact
at the design (:func:`~reflector_opt.optimiser._printed_walls.linearised_walls`), so that the
optimum sits on the wall's limit. The walls are minima over swept keep-outs laid out on 1° pose
grids, so they change in steps and their slopes are rough: a linear model taken far from the walls'
limit can mislead the polish (with no distance margin on a polished surface the repair wandered
from 0.069° to 0.104°, where the default 0.1 mm margin gives 0.075°). The distance window's
margin is the walls' smooth stand-in (it holds each sensor's channel away from the reflector's
swept space), so with a margin below the default setting's (:data:`STRICTER_MARGIN_MM`) the
repair runs along more paths from the polished point: the polish with the margin held at each
level of a fixed ladder above the problem's margin (:func:`stricter_levels`: 0.025, 0.05, …,
0.1 mm), then the walls' linear model from there, where it holds; the best design that passes
is kept. The polish with a margin held converges to the same design from wherever the search
left it (measured: every level gave the same objective, to 10⁻⁶, from the searches at 0,
0.02 and 0.05 mm on both surfaces), and a smaller margin's ladder holds every level of a
larger one's, so each stricter setting's held designs are candidates of a relaxed one: relaxing
the margin returns no worse a design. docs/optimiser.md has the figures and the table against
an independent search.
"""

import dataclasses
import math

from reflector_opt.optimiser._conditions import steered_constraints
from reflector_opt.optimiser._constraints import SMOOTH_CONSTRAINTS
from reflector_opt.optimiser._polish import polish
from reflector_opt.optimiser._printed_walls import DESIGNED_WALLS, PRINTED_WALL, linearised_walls
from reflector_opt.optimiser._problem import Problem
from reflector_opt.optimiser._variables import values_from_vector

#: Rounds of repair and polish along each path before a design that fails verification is
#: given up.
REPAIR_ROUNDS = 6

#: The default setting's distance margin (:class:`~reflector_opt.optimiser._problem.Problem`), mm:
#: a problem with a smaller one is also repaired along the stricter margins' paths.
STRICTER_MARGIN_MM = next(
    f.default for f in dataclasses.fields(Problem) if f.name == "distance_margin_mm"
)


#: Step of the ladder of distance margins the extra repair paths hold first, mm.
STRICTER_STEP_MM = 0.025


def stricter_levels(margin_mm):
    """The distance margins the extra repair paths hold first: the multiples of
    :data:`STRICTER_STEP_MM` above ``margin_mm`` up to :data:`STRICTER_MARGIN_MM`, mm.

    The ladder is the same for every margin: a smaller margin's levels include every level
    of a larger one.

    Parameters
    ----------
    margin_mm : float
        The problem's required distance margin, mm.

    Returns
    -------
    list of float
    """
    first = math.floor(margin_mm / STRICTER_STEP_MM + 1e-9) + 1
    last = round(STRICTER_MARGIN_MM / STRICTER_STEP_MM)
    return [round(n * STRICTER_STEP_MM, 12) for n in range(first, last + 1)]


def repair_tightening(evaluation, tightening, steered=()):
    """The tightening that steers the polish away from the per-pose failures of ``evaluation``.

    A failing smooth constraint, or one of ``steered`` (the polish holds them too), is
    tightened by 1.5× its shortfall. A failing printed wall
    that depends on the design (:data:`~reflector_opt.optimiser._printed_walls.DESIGNED_WALLS`)
    tightens nothing here (see :func:`verify`).

    Parameters
    ----------
    evaluation : reflector_opt.optimiser._evaluation.Evaluation
        A design on the workspace grid, its printed walls checked if every other
        constraint is met.
    tightening : mapping of str to float
        The extra margin (mm, or the constraint's unit) demanded so far.
    steered : tuple of str, optional
        Other constraints the polish holds
        (:func:`~reflector_opt.optimiser._conditions.steered_constraints`).

    Returns
    -------
    dict or None
        The new tightening, or None if some failure cannot be steered by the polish
        (uniqueness unless ``steered``, fold, a wall fixed by the CAD parameters, no valid
        layout).
    """
    if evaluation.error is not None:
        return None
    out = dict(tightening)
    for c in evaluation.constraints:
        if c.met:
            continue
        if c.name in SMOOTH_CONSTRAINTS or c.name in steered:
            out[c.name] = out.get(c.name, 0.0) + 1.5 * (-c.margin)
        elif c.name == PRINTED_WALL:
            walls = evaluation.printed_walls_mm
            if any(walls[w] < c.limit for w in walls if w not in DESIGNED_WALLS):
                return None
        else:
            return None
    return out


def _missed_walls(evaluation, walls, extra):
    """``extra`` raised by the shortfall of each wall the last linear model let fall short."""
    out = dict(extra)
    if walls is None:
        return out
    for name, limit in zip(walls.names, walls.limit, strict=True):
        shortfall = limit - evaluation.printed_walls_mm[name]
        if shortfall > 0:
            out[name] = out.get(name, 0.0) + shortfall
    return out


def _judged(problem, x, progress, evaluations):
    """The design at ``x`` on the workspace grid, its printed walls checked if it passes.

    ``progress`` is of the whole verification: how many repairs it needs is not known
    beforehand, so each judgement is shown as halving the work left.
    """
    if progress is not None:
        progress(1.0 - 0.5 ** evaluations["verify"], "verifying on the workspace grid")
    final = problem.evaluate(values_from_vector(problem.free_names, x, problem.fixed_values))
    evaluations["verify"] += 1
    if final.feasible:
        if progress is not None:
            progress(1.0 - 0.5 ** evaluations["verify"], "checking the printed walls")
        final = problem.check_printed(final)
    return final


def _repair(problem, x, final, stricter_mm, context):
    """Repair from ``x`` judged ``final``: at most :data:`REPAIR_ROUNDS` rounds of tightening,
    polish and judging; when a printed wall fails first with ``stricter_mm`` given, the polish
    holds the distance margin at ``stricter_mm`` before the walls' linear model is taken.

    Returns
    -------
    (Evaluation, dict, bool)
        The last judgement, the tightening and whether a printed wall failed on the way (if
        none did, every path is the same).
    """
    lower, upper, budget, progress, evaluations, map_ = context
    tightening, extra, walls, wall_failed = {}, {}, None, False
    for _ in range(REPAIR_ROUNDS):
        repaired = repair_tightening(final, tightening, steered_constraints(problem))
        if repaired is None:
            break  # failing a constraint the polish cannot steer
        tightening = repaired
        if final.printed_walls_mm is not None:  # every per-pose constraint met: a wall failed
            if stricter_mm is not None and not wall_failed:
                held = stricter_mm - problem.distance_margin_mm
                tightening["distance_margin_mm"] = max(
                    tightening.get("distance_margin_mm", 0), held
                )
            else:
                extra = _missed_walls(final, walls, extra)
                walls, layouts = linearised_walls(
                    problem, x, lower, upper, extra, final.printed_walls_mm, map_
                )
                evaluations["layouts"] = evaluations.get("layouts", 0) + layouts
                if walls is not None and walls.unreachable():
                    break  # no point within the bounds thickens it enough: not repairable
            wall_failed = True
        step, maxiter = budget.polish_step_deg, budget.polish_maxiter
        x, n = polish(problem, x, lower, upper, step, maxiter, tightening, walls, map_)
        evaluations["polish"] += n
        final = _judged(problem, x, progress, evaluations)
        if final.feasible:
            break
    return final, tightening, wall_failed


def verify(problem, x, lower, upper, budget, progress, evaluations, map_=map):
    """Evaluate on the workspace grid and check the printed walls, repairing what fails.

    A design that passes is returned as it is. One that fails is repaired
    (:func:`repair_tightening`; a printed wall by the walls' linear model, a wall that the
    model let fall short demanded that much thicker in the next round), at most
    :data:`REPAIR_ROUNDS` rounds. If a printed wall failed on the way and the distance
    margin is below :data:`STRICTER_MARGIN_MM`, the repair also runs from the same point
    with the margin held first at each of :func:`stricter_levels`, and the design with the
    best objective of those that pass is returned. ``map_`` (ordered like the builtin
    ``map``, e.g. a worker pool's) computes the walls' forward differences and the polish's.

    Returns
    -------
    (Evaluation, dict)
        The final evaluation (feasible or not) and the tightening its repair applied.
    """
    final = _judged(problem, x, progress, evaluations)
    if final.feasible:
        return final, {}
    context = (lower, upper, budget, progress, evaluations, map_)
    found = [_repair(problem, x, final, None, context)]
    if found[0][2] and problem.distance_margin_mm < STRICTER_MARGIN_MM:
        levels = stricter_levels(problem.distance_margin_mm)
        found += [_repair(problem, x, final, level, context) for level in levels]
    passed = [f for f in found if f[0].feasible]
    final, tightening, _ = min(passed, key=lambda f: f[0].objective) if passed else found[0]
    return final, tightening
