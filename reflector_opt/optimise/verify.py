"""Verification of a polished design on the workspace grid and of its printed walls, with repair.

The search and the polish judge a design on coarse pose grids; the design returned must pass
on the workspace grid (0.1°) and its printed parts must pass the CAD export's own wall check
(:func:`~reflector_opt.optimise.printed.check_printed`). If a per-pose constraint fails there
(it was met only on the coarser grid) or a printed wall is too thin, a smooth constraint is
tightened and the polish repeated, up to :data:`REPAIR_ROUNDS` times.
"""

from __future__ import annotations

from reflector_opt.optimise.constraints import SMOOTH_CONSTRAINTS
from reflector_opt.optimise.polish import polish
from reflector_opt.optimise.printed import PRINTED_WALL, PRINTED_WALL_PROXIES
from reflector_opt.optimise.variables import values_from_vector

__all__ = ["REPAIR_ROUNDS", "repair_tightening", "verify"]

#: Rounds of tighten-and-polish before a design that fails verification is given up.
REPAIR_ROUNDS = 4


def repair_tightening(evaluation, tightening):
    """The tightening that steers the polish away from every failure of ``evaluation``.

    A failing smooth constraint is tightened by 1.5× its shortfall. A failing printed wall is
    steered by its proxy (:data:`~reflector_opt.optimise.printed.PRINTED_WALL_PROXIES`),
    tightened so that the proxy must move by 1.5× the wall's shortfall: past its present
    margin, which the polish would otherwise keep.

    Returns
    -------
    dict or None
        The new tightening, or None if some failure cannot be steered by the polish
        (uniqueness, fold, a wall fixed by the CAD parameters, no valid layout).
    """
    if evaluation.error is not None:
        return None
    constraints = {c.name: c for c in evaluation.constraints}
    out = dict(tightening)
    for c in evaluation.constraints:
        if c.met:
            continue
        if c.name in SMOOTH_CONSTRAINTS:
            out[c.name] = out.get(c.name, 0.0) + 1.5 * (-c.margin)
        elif c.name == PRINTED_WALL:
            for wall, mm in evaluation.printed_walls_mm.items():
                proxy = PRINTED_WALL_PROXIES.get(wall)
                if mm >= c.limit:
                    continue
                if proxy is None:
                    return None
                slack = max(constraints[proxy].margin, 0.0)
                out[proxy] = out.get(proxy, 0.0) + slack + 1.5 * (c.limit - mm)
        else:
            return None
    return out


def verify(problem, x, lower, upper, budget, progress, evaluations):
    """Evaluate on the workspace grid and check the printed walls, repairing what fails.

    A per-pose constraint that fails on the workspace grid (it was met only on the coarser
    grid) or a printed wall below the minimum is repaired by tightening a smooth constraint
    and polishing again (:func:`repair_tightening`), up to :data:`REPAIR_ROUNDS` times.

    Returns
    -------
    (Evaluation, dict)
        The final evaluation (feasible or not) and the tightening the repair applied.
    """
    tightening = {}
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
        x, n = polish(
            problem, x, lower, upper, budget.polish_step_deg, budget.polish_maxiter, tightening
        )
        evaluations["polish"] += n
    return final, tightening
