"""Verification of a polished design on the workspace grid and of its printed walls, with repair.

The search and the polish judge a design on coarse pose grids; the design returned must pass
on the workspace grid (0.1°) and its printed parts must pass the CAD export's own wall check
(:func:`~reflector_opt.optimise.printed.check_printed`). If a per-pose constraint fails there
(it was met only on the coarser grid), it is tightened; if a printed wall is too thin, the
designed walls become linear constraints of the polish, exact at the design
(:func:`~reflector_opt.optimise.printed.linearised_walls`); the polish is repeated, up to
:data:`REPAIR_ROUNDS` times.
"""

from __future__ import annotations

from reflector_opt.optimise.constraints import SMOOTH_CONSTRAINTS
from reflector_opt.optimise.polish import polish
from reflector_opt.optimise.printed import DESIGNED_WALLS, PRINTED_WALL, linearised_walls
from reflector_opt.optimise.variables import values_from_vector

__all__ = ["REPAIR_ROUNDS", "repair_tightening", "verify"]

#: Rounds of repair and polish before a design that fails verification is given up.
REPAIR_ROUNDS = 6


def repair_tightening(evaluation, tightening):
    """The tightening that steers the polish away from the per-pose failures of ``evaluation``.

    A failing smooth constraint is tightened by 1.5× its shortfall. A failing printed wall
    that depends on the design (:data:`~reflector_opt.optimise.printed.DESIGNED_WALLS`) is
    left to the walls' own linear model (see :func:`verify`) and tightens nothing.

    Returns
    -------
    dict or None
        The new tightening, or None if some failure cannot be steered by the polish
        (uniqueness, fold, a wall fixed by the CAD parameters, no valid layout).
    """
    if evaluation.error is not None:
        return None
    out = dict(tightening)
    for c in evaluation.constraints:
        if c.met:
            continue
        if c.name in SMOOTH_CONSTRAINTS:
            out[c.name] = out.get(c.name, 0.0) + 1.5 * (-c.margin)
        elif c.name == PRINTED_WALL:
            fixed = (w for w in evaluation.printed_walls_mm if w not in DESIGNED_WALLS)
            if any(evaluation.printed_walls_mm[w] < c.limit for w in fixed):
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


def verify(problem, x, lower, upper, budget, progress, evaluations, map_=map):
    """Evaluate on the workspace grid and check the printed walls, repairing what fails.

    A per-pose constraint that fails on the workspace grid is tightened
    (:func:`repair_tightening`). A printed wall below the minimum makes the designed walls,
    linearised at the present point by the export's own layout, constraints of the next
    polish; a wall that the linear model let fall short is demanded that much thicker in the
    next round. At most :data:`REPAIR_ROUNDS` rounds. ``map_`` (ordered like the builtin
    ``map``, e.g. a worker pool's) computes the walls' forward differences and the polish's.

    Returns
    -------
    (Evaluation, dict)
        The final evaluation (feasible or not) and the tightening the repair applied.
    """
    tightening, extra, walls = {}, {}, None
    for round_ in range(REPAIR_ROUNDS + 1):
        if progress is not None:
            progress(1.0, "verifying on the workspace grid")
        values = values_from_vector(problem.free_names, x, problem.fixed_values)
        final = problem.evaluate(values)
        evaluations["verify"] += 1
        if final.feasible:
            if progress is not None:
                progress(1.0, "checking the printed walls")
            final = problem.check_printed(final)
        if final.feasible or round_ == REPAIR_ROUNDS:
            break
        repaired = repair_tightening(final, tightening)
        if repaired is None:
            break  # failing a constraint the polish cannot steer
        tightening = repaired
        if final.printed_walls_mm is not None:  # every per-pose constraint met: a wall failed
            extra = _missed_walls(final, walls, extra)
            walls, layouts = linearised_walls(
                problem, x, lower, upper, extra, final.printed_walls_mm, map_
            )
            evaluations["layouts"] = evaluations.get("layouts", 0) + layouts
        x, n = polish(
            problem,
            x,
            lower,
            upper,
            budget.polish_step_deg,
            budget.polish_maxiter,
            tightening,
            walls,
            map_,
        )
        evaluations["polish"] += n
    return final, tightening
