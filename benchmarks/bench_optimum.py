"""Is the optimiser on the optimum? A dense independent search for each part, surface and margin.

Run from the repository root:

    python benchmarks/bench_optimum.py --part NJL5901R-2 VCNT2020 --margin 0 0.02 0.05 0.1 0.15
        [--surface white-sla-resin polished] [--points 2048 --starts 2] [--cache FILE.json]

For each catalogue part (:func:`~reflector_opt.optimiser._sensor_choice.part_problem`, the
default envelope), surface and required distance margin it runs, independently of the
optimiser's own search (no code shared with :mod:`reflector_opt.optimiser._search`,
:mod:`~reflector_opt.optimiser._polish`, :mod:`~reflector_opt.optimiser._fused_objective` or
:mod:`~reflector_opt.optimiser._verify`):

1. a screen of a scrambled Sobol sequence over the problem's bounds, each point scored by the
   public evaluation (:meth:`Problem.evaluate`) on the 3° grid;
2. from the best few (feasible first, then the least violation), a derivative-free local
   search: COBYLA (scipy) on the worst-case objective on the 2° grid subject to every
   constraint's margin there and to the thinnest printed wall by the CAD export's check
   (:meth:`Problem.check_printed`), then a pattern search of its own (coordinate and random
   directions, the step halved when no direction improves) from COBYLA's point, a move being
   accepted only if the design meets every constraint and its printed parts pass;
3. the best point re-verified on the workspace grid (0.1°) with the printed walls; the margins
   run from the largest down, and a stricter margin's best design that passes at a smaller
   one is a candidate there too (it meets the smaller margin).

It then runs ``optimise`` on the same problem (default budget, seed 0) and prints both
objectives (the worst-case resolution with the isotropy weight, what both minimise) and their
difference: the optimiser is on the optimum if it is at most 0.5 % worse than the best
printable design the independent search finds. ``--cache`` keeps the independent searches'
results, so that the optimiser can be judged again without repeating them.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import minimize
from scipy.stats import qmc

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from reflector_opt.model._catalogue import get_part  # noqa: E402
from reflector_opt.model._surface import get_material  # noqa: E402
from reflector_opt.optimiser import Problem, optimise  # noqa: E402
from reflector_opt.optimiser._sensor_choice import part_problem  # noqa: E402
from reflector_opt.optimiser._variables import VARIABLES  # noqa: E402

#: Score of a design that breaks a constraint (plus its violations) or is no design at all.
INFEASIBLE = 1.0e3


class Scorer:
    """Objective of a point of [0, 1]^n on a pose grid by the public evaluation path."""

    def __init__(self, problem, step_deg):
        self.problem = problem
        self.step_deg = step_deg
        self.names = [v.name for v in VARIABLES]
        bounds = problem.search_bounds
        self.lower = np.array([bounds[n][0] for n in self.names])
        self.upper = np.array([bounds[n][1] for n in self.names])
        self.free = self.upper > self.lower
        self.calls = 0
        self.layouts = 0

    def values(self, u):
        x = self.lower.copy()
        x[self.free] += np.clip(u, 0.0, 1.0) * (self.upper - self.lower)[self.free]
        return dict(zip(self.names, x.tolist(), strict=True))

    def evaluation(self, u):
        self.calls += 1
        return self.problem.evaluate(self.values(u), self.step_deg, checked=False)

    def score(self, u):
        """Objective if every grid constraint is met, else INFEASIBLE + the violations."""
        e = self.evaluation(u)
        if e.feasible and np.isfinite(e.objective):
            return e.objective, e
        return INFEASIBLE + e.violation, e

    def printable(self, evaluation):
        self.layouts += 1
        return self.problem.check_printed(evaluation).feasible


def screen(scorer, points, seed):
    """Sobol points scored on the scorer's grid, best first: list of (score, u)."""
    n = int(np.sum(scorer.free))
    sample = qmc.Sobol(n, scramble=True, seed=seed).random(points)
    scored = [(scorer.score(u)[0], u) for u in sample]
    return sorted(scored, key=lambda t: t[0])


def pattern_search(scorer, u0, rng, step=0.05, min_step=2e-4, max_calls=1500):
    """Derivative-free descent; a move is accepted only if it is feasible and printable."""
    n = u0.size
    u = u0.copy()
    best, e = scorer.score(u)
    if best >= INFEASIBLE or not scorer.printable(e):
        return None, None
    start = scorer.calls
    while step >= min_step and scorer.calls - start < max_calls:
        random = rng.standard_normal((n, n))
        directions = np.vstack(
            [np.eye(n), -np.eye(n), random / np.linalg.norm(random, axis=1)[:, None]]
        )
        moved = False
        for d in directions:
            trial = np.clip(u + step * d, 0.0, 1.0)
            value, e = scorer.score(trial)
            if value < best and value < INFEASIBLE and scorer.printable(e):
                u, best, moved = trial, value, True
                break
        if not moved:
            step *= 0.5
    return best, u


def cobyla(scorer, u0, max_calls=250):
    """COBYLA from u0: objective and every scaled constraint margin, printed walls included."""
    problem = scorer.problem
    width = len(problem.evaluate_design(problem.baseline_design(), scorer.step_deg).constraints)
    width += 1  # the printed walls
    cache = {}

    def judged(u):
        key = np.asarray(u).tobytes()
        if key not in cache:
            e = scorer.evaluation(u)
            checked = e
            if e.error is None and np.isfinite(e.objective):
                scorer.layouts += 1
                checked = problem.check_printed(e)
            if checked.error is not None or not np.isfinite(e.objective):
                cache[key] = (10.0, np.full(width, -1.0))  # no design: everything violated
            else:
                margins = [c.margin / c.scale for c in checked.constraints]
                cache[key] = (e.objective, np.array(margins))
        return cache[key]

    res = minimize(
        lambda u: judged(u)[0],
        u0,
        method="COBYLA",
        constraints=[{"type": "ineq", "fun": lambda u: judged(u)[1]}],
        bounds=[(0.0, 1.0)] * u0.size,
        options={"maxiter": max_calls, "rhobeg": 0.05, "tol": 1e-6},
    )
    return np.clip(res.x, 0.0, 1.0)


def independent_optimum(problem, points, starts, seed):
    coarse, fine = Scorer(problem, 3.0), Scorer(problem, 2.0)
    ranked = screen(coarse, points, seed)
    feasible = [u for s, u in ranked if s < INFEASIBLE]
    rng = np.random.default_rng(seed)
    found = []
    for _, u in ranked[:starts]:  # feasible first, then the least violation
        value, u_best = pattern_search(fine, cobyla(fine, u), rng)
        if value is not None:
            found.append((value, u_best))
    if not found:
        return None
    found.sort(key=lambda t: t[0])
    verified = []
    for _, u in found:
        e = problem.check_printed(problem.evaluate(fine.values(u)))
        if e.feasible:
            verified.append(e)
    best = min(verified, key=lambda e: e.objective) if verified else None
    return best, {
        "screened": points,
        "feasible_in_screen": len(feasible),
        "evaluations": coarse.calls + fine.calls,
        "layouts": fine.layouts,
    }


def _problem(part_name, surface, margin):
    """The default problem with a catalogue part, a surface and a distance margin (mm)."""
    problem = Problem(surface=get_material(surface), distance_margin_mm=margin)
    return part_problem(problem, get_part(part_name))


def _reference(problem, args, stricter):
    """The independent search's best printable design at ``problem``, or the best of the
    stricter margins' references that passes here (a design meeting a stricter margin meets
    a looser one, so the true optimum is no worse than any of them); the evaluation or None."""
    found = independent_optimum(problem, args.points, args.starts, args.seed)
    candidates = [] if found is None or found[0] is None else [found[0]]
    for values in stricter:
        e = problem.check_printed(problem.evaluate(values))
        if e.feasible:
            candidates.append(e)
    return min(candidates, key=lambda e: e.objective) if candidates else None


def _cases(args):
    for part in args.part:
        for surface in args.surface:
            # strictest first, so that each reference can take the stricter ones' designs
            for margin in sorted(args.margin, reverse=True):
                yield part, surface, margin


def _load(path):
    return json.loads(path.read_text()) if path is not None and path.exists() else {}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--part", nargs="+", default=["NJL5901R-2"])
    parser.add_argument("--surface", nargs="+", default=["white-sla-resin", "polished"])
    parser.add_argument("--margin", nargs="+", type=float, default=[0.1])
    parser.add_argument("--points", type=int, default=4096)
    parser.add_argument("--starts", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--cache", type=Path, help="JSON file keeping the independent searches' results"
    )
    args = parser.parse_args()
    print("load average {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    cache, rows, stricter = _load(args.cache), [], {}
    for part, surface, margin in _cases(args):
        key = f"{part}|{surface}|{margin:g}|{args.points}|{args.starts}|{args.seed}"
        problem = _problem(part, surface, margin)
        t0 = time.perf_counter()
        if key not in cache:
            best = _reference(problem, args, stricter.get((part, surface), []))
            cache[key] = (
                None
                if best is None
                else {
                    "values": best.values,
                    "worst_deg": best.metrics.worst_resolution_deg,
                    "objective": best.objective,
                }
            )
            if args.cache is not None:
                args.cache.write_text(json.dumps(cache, indent=1))
        t_independent = time.perf_counter() - t0
        if cache[key] is None:
            print(f"{part}, {surface}, {margin:g} mm: no printable design found")
            continue
        stricter.setdefault((part, surface), []).append(cache[key]["values"])
        t0 = time.perf_counter()
        result = optimise(problem, seed=0)
        t_optimiser = time.perf_counter() - t0
        mine, theirs = result.objective, cache[key]["objective"]
        gap = mine / theirs - 1.0
        worst = (result.evaluation.metrics.worst_resolution_deg, cache[key]["worst_deg"])
        rows.append((part, surface, margin, *worst, mine, theirs, gap))
        print(
            f"{part}, {surface}, {margin:g} mm: optimiser {mine:.5f}° ({t_optimiser:.1f} s), "
            f"independent search {theirs:.5f}° ({t_independent:.0f} s); optimiser "
            f"{100 * gap:+.2f} % ({'within' if gap <= 0.005 else 'NOT within'} 0.5 %)",
            flush=True,
        )
    print(
        "\n| part | surface | margin (mm) | worst-case 1σ: optimiser | independent | "
        "objective: optimiser | independent | difference |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for part, surface, margin, w_mine, w_theirs, mine, theirs, gap in rows:
        print(
            f"| {part} | {surface} | {margin:g} | {w_mine:.4f}° | {w_theirs:.4f}° | "
            f"{mine:.4f}° | {theirs:.4f}° | {100 * gap:+.2f} % |"
        )
    print("load average {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))


if __name__ == "__main__":
    main()
