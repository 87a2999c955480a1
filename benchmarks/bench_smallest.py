"""The size–accuracy frontier over the shipped catalogue: its wall time, each point against an
independent search, and a warm start from the larger neighbour against cold searches.

    python benchmarks/bench_smallest.py                      # the frontier of every part, timed
    python benchmarks/bench_smallest.py --check              # + each point against seed + 1
    python benchmarks/bench_smallest.py --starts 1 --check   # one search a point, as before
    python benchmarks/bench_smallest.py --warm NJL5901R-2,VCNT2020   # reuse against cold

The frontier is ``size_frontier`` as ``reflector-opt smallest --sensor auto --workspace-deg
11`` runs it: the default search budget, each point the best of ``--starts`` (3) searches,
the parts as tasks of ``--workers`` local processes (each part's sizes in order in one task),
progress printed as each part ends, the load average before and after. ``--check``
searches every feasible size again, independently (seed + 1, one search, the same budget),
and prints the frontier's objective over the independent one and how many exceed 1.005.
``--warm`` runs, for the parts named and at each feasible size of their frontier, a cold
search and one whose initial population holds the optimum of the next larger size
(``optimise(initial=…)``, same budget, one member of an otherwise cold Latin hypercube), one
process each, and prints both objectives, evaluations and seconds.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time

from reflector_opt.design import Workspace
from reflector_opt.design._bearings import shipped_bearings
from reflector_opt.model._catalogue import get_part, shipped_catalogue
from reflector_opt.optimiser import Problem, SearchBudget
from reflector_opt.optimiser._search import optimise
from reflector_opt.optimiser._size import SizeStudy, size_frontier, size_problem
from reflector_opt.util._errors import InputError


def _load():
    return "load average {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def frontier(study, parts):
    """Every part's frontier, timed; prints the rows and the wall time."""
    print(_load())
    t0 = time.perf_counter()
    points = size_frontier(study, parts, progress=lambda f, m: print(f"  {100 * f:5.1f} % {m}"))
    wall = time.perf_counter() - t0
    print("part          mm    objective  searched   from  binding")
    for row, _, _ in points:
        if row["status"] != "feasible":
            print(f"{row['part']:<12} {row['unit_diameter_mm']:5g}  no design: {row['binding']}")
            continue
        carried = row.get("carried_from_mm")
        print(
            f"{row['part']:<12} {row['unit_diameter_mm']:5g}  {row['objective_deg']:.4f}°   "
            f"{row['searched_deg']:.4f}°  {'' if carried is None else f'{carried:g}':>5}  "
            f"{row['binding']}"
        )
    n = sum(1 for _ in points)
    print(
        f"\n{len(parts)} parts, {n} points in {wall:.1f} s wall on {study.budget.workers} "
        f"processes, {study.starts} searches a point"
    )
    print(_load())
    return points


def check(study, points):
    """Each feasible point against an independent search at its size (seed + 1)."""
    ratios = []
    for row, _, _ in points:
        if row["status"] != "feasible":
            continue
        part = get_part(row["part"])
        problem = size_problem(study.problem, part, row["unit_diameter_mm"], row["bearing"])
        try:
            other = optimise(problem, seed=study.seed + 1, budget=study.budget).objective
        except InputError as exc:
            print(f"{row['part']:<12} {row['unit_diameter_mm']:5g}  independent: {exc}")
            continue
        ratios.append(row["objective_deg"] / other)
        print(
            f"{row['part']:<12} {row['unit_diameter_mm']:5g}  frontier {row['objective_deg']:.4f}°"
            f"  independent {other:.4f}°  ratio {ratios[-1]:.4f}"
        )
    over = sum(r > 1.005 for r in ratios)
    print(f"worst ratio {max(ratios):.4f} over {len(ratios)} points, {over} above 1.005")


def _run(problem, study, initial):
    """(result or the reason none passed, evaluations, seconds) of one search."""
    t0 = time.perf_counter()
    try:
        result = optimise(problem, seed=study.seed, budget=study.budget, initial=initial)
    except InputError as exc:
        return str(exc), 0, time.perf_counter() - t0
    return result, sum(result.evaluations.values()), time.perf_counter() - t0


def _said(run):
    if isinstance(run[0], str):
        return f"no design ({run[0][:60]}…, {run[2]:.1f} s)"
    return f"{run[0].objective:.4f}° ({run[1]} ev, {run[2]:.1f} s)"


def warm(study, points, names):
    """Cold against a warm initial population, size by size, for the parts named."""
    one = dataclasses.replace(study, budget=dataclasses.replace(study.budget, workers=1))
    totals = {"cold": [0, 0.0], "warm": [0, 0.0]}
    worse = 0
    for name in names:
        part, previous = get_part(name), None
        rows = [p[0] for p in points if p[0]["part"] == name and p[0]["status"] == "feasible"]
        for row in sorted(rows, key=lambda r: -r["unit_diameter_mm"]):
            problem = size_problem(study.problem, part, row["unit_diameter_mm"], row["bearing"])
            cold = _run(problem, one, None)
            if previous is None:
                previous = None if isinstance(cold[0], str) else dict(cold[0].evaluation.values)
                continue
            hot = _run(problem, one, previous)
            print(f"{name:<12} {row['unit_diameter_mm']:5g}  cold {_said(cold)}  warm {_said(hot)}")
            if isinstance(hot[0], str) or isinstance(cold[0], str):
                worse += isinstance(hot[0], str) and not isinstance(cold[0], str)
                continue
            previous = dict(hot[0].evaluation.values)
            for key, (_, n, s) in (("cold", cold), ("warm", hot)):
                totals[key][0] += n
                totals[key][1] += s
            worse += hot[0].objective > cold[0].objective * 1.0001
    print(
        f"totals: cold {totals['cold'][0]} ev, {totals['cold'][1]:.1f} s; warm "
        f"{totals['warm'][0]} ev, {totals['warm'][1]:.1f} s; warm worse at {worse} sizes"
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--workspace-deg", type=float, default=11.0)
    parser.add_argument("--sensor", default=None, help="parts by commas (default: all)")
    parser.add_argument("--starts", type=int, default=3, help="searches per point (3)")
    parser.add_argument("--check", action="store_true")
    parser.add_argument("--warm", default=None, metavar="PARTS")
    args = parser.parse_args()
    w = args.workspace_deg
    study = SizeStudy(
        Problem(workspace=Workspace((-w, w), (-w, w))),
        shipped_bearings(),
        seed=args.seed,
        budget=SearchBudget(workers=args.workers),
        starts=args.starts,
    )
    names = None if args.sensor is None else args.sensor.split(",")
    parts = list(shipped_catalogue()) if names is None else [get_part(n) for n in names]
    points = frontier(study, parts)
    if args.check:
        check(study, points)
    if args.warm:
        warm(study, points, args.warm.split(","))


if __name__ == "__main__":
    main()
