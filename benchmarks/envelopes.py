"""The optimiser over envelopes: does the last check ever refuse what the search took for
feasible?

    python benchmarks/envelopes.py               # every envelope, a table row each, in use
    python benchmarks/envelopes.py --only 18     # the envelopes of one unit diameter
    python benchmarks/envelopes.py --objective resolution   # the white-noise objective

Each envelope (unit diameter, catalogue part, workspace ±W°) is one ``optimise`` run as
``reflector-opt smallest`` makes a point: the part's problem at that diameter on the smallest
catalogue bearing whose stop covers the workspace (:func:`~reflector_opt.optimiser._size.
size_problem`), the same last check as the command (the 0.1° workspace grid, then the printed
walls by the export's layout), one start, a small search budget (:data:`BUDGET`). Each row
says how the run ended: ``design`` (objective, the binding constraint, the thinnest printed
wall), ``no fit`` (the settings' pre-check: no point within the bounds meets them), ``search``
(no feasible point found) or ``last check`` (the search's point refused on the fine grid or
by the printed walls, with the constraint and its shortfall). The Markdown table is
docs/optimiser.md's.
"""

from __future__ import annotations

import argparse
import time

from reflector_opt.design import Workspace
from reflector_opt.design._bearings import shipped_bearings
from reflector_opt.model._catalogue import get_part, shipped_catalogue
from reflector_opt.optimiser import Problem, SearchBudget
from reflector_opt.optimiser._conditions import search_conditions
from reflector_opt.optimiser._search import optimise
from reflector_opt.optimiser._size import choose_bearing, size_problem
from reflector_opt.util._errors import InputError, NoDesignError
from reflector_opt.util._limits import OBJECTIVES

#: The search budget of every run: small, the last check the command's.
BUDGET = SearchBudget(popsize=4, maxiter=10, polish_maxiter=30, workers=1)

_PARTS = [p.name for p in shipped_catalogue()]

#: (unit diameter mm, part, workspace ±deg): every part at 24 and 22 mm, the two smallest
#: parts down to 16 mm, workspaces ±8° to ±15°.
ENVELOPES = (
    *[(24.0, p, 15.0) for p in _PARTS],
    *[(22.0, p, 10.0) for p in _PARTS],
    *[(20.0, p, w) for p in ("NJL5901R-2", "VCNT2020") for w in (8.0, 12.0)],
    (18.0, "NJL5901R-2", 12.0),
    (18.0, "VCNT2020", 12.0),
    (18.0, "VCNT2020", 8.0),
    (16.0, "NJL5901R-2", 8.0),
    (16.0, "VCNT2020", 8.0),
)


def run(diameter_mm, part, half_deg, seed=0, objective="in-use"):
    """One envelope's run: (outcome, objective or None, detail, seconds); ``objective`` as
    ``--objective`` (in use: the default conditions)."""
    t0 = time.perf_counter()
    workspace = Workspace((-half_deg, half_deg), (-half_deg, half_deg))
    try:
        bearing = choose_bearing(shipped_bearings(), workspace, diameter_mm)
        base = Problem(workspace=workspace, conditions=search_conditions(objective, None))
        problem = size_problem(base, get_part(part), diameter_mm, bearing.name)
    except InputError as exc:
        return "no fit", None, str(exc), time.perf_counter() - t0
    try:
        result = optimise(problem, seed=seed, budget=BUDGET)
    except NoDesignError as exc:
        kind = "last check" if "verification" in str(exc) else "search"
        return kind, None, str(exc), time.perf_counter() - t0
    e = result.evaluation
    walls = e.printed_walls_mm
    thinnest = min(walls, key=walls.get)
    binding = min(e.constraints, key=lambda c: c.margin / c.scale if c.limit else float("inf"))
    detail = (
        f"{bearing.name}; binding {binding.name} (margin {binding.margin:.3g} {binding.unit}); "
        f"thinnest printed wall {thinnest} {walls[thinnest]:.3f} mm"
    )
    return "design", float(e.objective), detail, time.perf_counter() - t0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", type=float, help="only the envelopes of this diameter, mm")
    parser.add_argument("--objective", choices=OBJECTIVES, default=OBJECTIVES[0])
    args = parser.parse_args()
    rows = [e for e in ENVELOPES if args.only is None or e[0] == args.only]
    print("| unit | part | workspace | outcome | objective | detail | s |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    counts = {}
    for diameter, part, half in rows:
        outcome, objective, detail, seconds = run(diameter, part, half, 0, args.objective)
        counts[outcome] = counts.get(outcome, 0) + 1
        shown = "" if objective is None else f"{objective:.4f}°"
        print(
            f"| {diameter:g} mm | {part} | ±{half:g}° | {outcome} | {shown} | {detail} | "
            f"{seconds:.0f} |",
            flush=True,
        )
    print(", ".join(f"{k}: {v}" for k, v in counts.items()))


if __name__ == "__main__":
    main()
