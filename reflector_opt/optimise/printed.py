"""The walls of the printed parts, judged on the final design by the CAD export's own rules.

``printed_wall_mm`` is judged on the final design only (:func:`check_printed`, about 1 s):
the search and the polish steer by its cheap proxies, ``wall_mm`` (the shell under the light
spots), ``distance_margin_mm`` (the reflector's clearance in front of the sensors, which sets
the body wall behind each sensor channel), ``reflector_envelope_mm`` (the swept space inside
the unit) and ``window_wall_mm`` (exact: the wall above a sensor window depends on the
sensors alone); :data:`PRINTED_WALL_PROXIES` maps each printed wall to the proxy whose
tightening thickens it.
"""

from __future__ import annotations

from dataclasses import replace

from reflector_opt.design.layout import plan_layout
from reflector_opt.optimise.constraints import Constraint
from reflector_opt.util.errors import InputError

__all__ = ["PRINTED_WALL", "PRINTED_WALL_PROXIES", "check_printed"]

#: Name of the constraint on the walls of the printed parts.
PRINTED_WALL = "printed_wall_mm"

#: The printed walls (``"part: wall"``, see :func:`reflector_opt.design.layout.plan_layout`) that
#: depend on the design variables, and the smooth constraint whose tightening thickens each.
#: The other walls are fixed by the CAD parameters and the mechanics.
PRINTED_WALL_PROXIES = {
    "reflector: reflecting shell": "wall_mm",
    "body: wall behind a sensor channel": "distance_margin_mm",
    "body: wall outside the swept space": "reflector_envelope_mm",
    "body: wall between a tendon hole and the swept space": "reflector_envelope_mm",
    "body: wall above a sensor window": "window_wall_mm",
}


def check_printed(problem, evaluation):
    """Add the walls of the printed parts to an evaluation, by the CAD export's rules.

    The layout of both parts (:func:`reflector_opt.design.layout.plan_layout`, the function the
    CAD export builds from) gives every designed wall; the thinnest becomes the
    constraint ``printed_wall_mm`` (≥ ``mechanics.min_wall_mm``), its ``detail`` naming
    the wall. A design the parts cannot be laid out for at all becomes invalid, with the
    layout's reason.

    Parameters
    ----------
    problem : reflector_opt.optimise.problem.Problem
        Its ``cad`` parameters and minimum wall.
    evaluation : reflector_opt.optimise.evaluation.Evaluation
        A valid candidate, usually on the workspace grid.

    Returns
    -------
    reflector_opt.optimise.evaluation.Evaluation
        With ``printed_walls_mm`` filled in (unchanged if ``evaluation`` is not valid).
    """
    if evaluation.error is not None or evaluation.design is None:
        return evaluation
    try:
        layout = plan_layout(evaluation.design, problem.cad)
    except InputError as exc:
        return replace(evaluation, error=f"printed parts: {exc}")
    walls = {f"reflector: {k}": float(v) for k, v in layout.reflector_walls_mm.items()}
    walls |= {f"body: {k}": float(v) for k, v in layout.body_walls_mm.items()}
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
