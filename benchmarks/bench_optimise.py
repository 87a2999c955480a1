"""Benchmark of ``reflector-opt optimise``: one evaluation, the search and the command end to end.

Run from the repository root:

    python benchmarks/bench_optimise.py [--baseline COMMIT] [--repeats N]

Prints, for the built-in defaults, each speed-up as a ratio measured in this one run (the two
sides alternate, so that the machine's load falls on both alike):

* one candidate's evaluation on the 3° search grid: the straightforward path
  (:class:`~reflector_opt.optimiser._evaluation.PenalisedObjective`: a ``Design``, the forward
  model on the stencil, the metrics' array functions) against the fused path
  (:class:`~reflector_opt.optimiser._fused_objective.FusedObjective`), over the same candidates,
  with the largest difference of their results;
* ``reflector-opt optimise --no-report`` end to end, in a fresh process, of the working tree
  against the baseline commit (checked out in a temporary worktree,
  :mod:`benchmarks.baseline`), in seconds and as a ratio, with each side's worst-case
  resolution and the search's and the polish and verification's seconds it records;
* the start-up before a search (the imports, the first evaluation with numba's kernels
  loaded), in fresh processes;
* the global search alone with 1 and 2 worker processes (the population split between them);
* a multi-start run (4 starts) on 1, 2 and 4 spawned local processes, and whether each gives
  the same design;
* the machine's load average before and after, since the cores are shared.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.baseline import checkout, run_script  # noqa: E402
from reflector_opt.optimiser import Problem, SearchBudget, optimise  # noqa: E402
from reflector_opt.optimiser._evaluation import PenalisedObjective  # noqa: E402
from reflector_opt.optimiser._fused_objective import FusedObjective  # noqa: E402
from reflector_opt.util._pools import local_processes  # noqa: E402

#: main when the fused evaluation and the exact printed walls were written.
BASELINE_COMMIT = "7dc9dbd"

#: The default design's optimum (white SLA resin), around which candidates are sampled.
OPTIMUM = {
    "gap_mm": 0.8312,
    "centre_along_mm": 0.9427,
    "centre_z_mm": 0.7989,
    "sensor_radius_mm": 10.0,
    "sensor_height_mm": 0.2768,
    "sensor_tilt_deg": 3.3357,
    "sensor_separation_deg": 84.086,
}

#: Warms a tree's compiled kernels (numba's cache) before it is timed.
WARM_UP = """
import json, reflector_opt
from reflector_opt.optimiser import Problem
from reflector_opt.optimiser._search import optimise, SearchBudget
from reflector_opt.util._errors import InputError
try:  # a search of two candidates compiles what a search needs, feasible or not
    optimise(Problem(), budget=SearchBudget(popsize=1, maxiter=1, polish_maxiter=0, workers=1))
except InputError:
    pass
print(json.dumps({"package": reflector_opt.__file__}))
"""


#: The fixed cost before a search can start, in a fresh process: the imports of the command's
#: optimisation, then its first evaluation (numba's cached kernels loaded).
START_UP = """
import json, time
t0 = time.perf_counter()
import reflector_opt.optimiser._config, reflector_opt.optimiser._search
from reflector_opt.optimiser import Problem, SearchBudget
from reflector_opt.optimiser._fused_objective import search_objective
t1 = time.perf_counter()
problem = Problem()
bounds = [problem.search_bounds[n] for n in problem.free_names]
objective = search_objective(problem, SearchBudget().grid_step_deg)
objective([0.5 * (lo + hi) for lo, hi in bounds])
t2 = time.perf_counter()
print(json.dumps({"package": reflector_opt.__file__, "imports": t1 - t0, "first": t2 - t1}))
"""


def start_up(repeats=3):
    """Median seconds of the imports and of the first evaluation, each in a fresh process."""
    runs = [run_script(ROOT, START_UP) for _ in range(repeats)]
    return {k: statistics.median(r[k] for r in runs) for k in ("imports", "first")}


def load():
    return "load average {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def candidates(problem, n=60, seed=0):
    """Half near the optimum (σ 5 % of each range), half uniform over the bounds."""
    names = problem.free_names
    lower = np.array([problem.search_bounds[k][0] for k in names])
    upper = np.array([problem.search_bounds[k][1] for k in names])
    rng = np.random.default_rng(seed)
    x0 = np.array([OPTIMUM[k] for k in names])
    near = x0 + 0.05 * (upper - lower) * rng.standard_normal((n // 2, len(names)))
    spread = lower + (upper - lower) * rng.random((n - n // 2, len(names)))
    return np.clip(np.vstack([near, spread]), lower, upper)


def evaluation_costs(problem, step_deg, xs, rounds=3):
    """Seconds per evaluation of both paths (median of alternating rounds) and their results."""
    paths = {
        "straightforward": PenalisedObjective(problem, step_deg),
        "fused": FusedObjective(problem, step_deg),
    }
    results = {k: np.array([f(x) for x in xs]) for k, f in paths.items()}  # also warms up
    times = {k: [] for k in paths}
    for _ in range(rounds):
        for key, f in paths.items():
            t0 = time.perf_counter()
            for x in xs:
                f(x)
            times[key].append((time.perf_counter() - t0) / len(xs))
    return {k: statistics.median(v) for k, v in times.items()}, results


def end_to_end(tree, out):
    """Seconds of ``python -m reflector_opt optimise --no-report`` in ``tree``, and its result."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    t0 = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "reflector_opt", "optimise", "--no-report", "--quiet", "--out", out],
        cwd=tree,
        env=env,
        check=True,
        capture_output=True,
    )
    seconds = time.perf_counter() - t0
    design = json.loads((Path(out) / "design.json").read_text())
    return seconds, design["predicted"]


def warm(tree):
    env = {**os.environ, "PYTHONPATH": str(tree)}
    subprocess.run(
        [sys.executable, "-c", WARM_UP], cwd=tree, env=env, check=True, capture_output=True
    )


def _worst(predicted):
    """The worst-case 1σ resolution a design.json's ``predicted`` block records, degrees."""
    resolution = predicted["metrics"]["resolution_deg"]
    return round(max(resolution["pitch_worst"], resolution["roll_worst"]), 5)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default=BASELINE_COMMIT)
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    print(f"{os.cpu_count()} cores, {load()}")

    problem, budget = Problem(), SearchBudget()
    xs = candidates(problem)
    cost, results = evaluation_costs(problem, budget.grid_step_deg, xs)
    a, b = results["straightforward"], results["fused"]
    feasible = (a < 1e5) & (b < 1e5)
    poses = len(problem.workspace.axes(budget.grid_step_deg)[0]) ** 2
    print(
        f"one evaluation on the {budget.grid_step_deg}° search grid ({poses} poses), "
        f"{len(xs)} candidates: straightforward {cost['straightforward'] * 1e3:.2f} ms, "
        f"fused {cost['fused'] * 1e3:.2f} ms "
        f"({cost['straightforward'] / cost['fused']:.1f}× lower)"
    )
    print(
        f"  results: same feasibility for {int(np.sum((a < 1e5) == (b < 1e5)))}/{len(xs)}; "
        f"largest relative difference of the objective over the {int(feasible.sum())} "
        f"feasible ones {np.max(np.abs(b[feasible] / a[feasible] - 1)):.1e}"
    )

    with checkout(args.baseline) as tree, tempfile.TemporaryDirectory() as tmp:
        sides = {"baseline": tree, "now": ROOT}
        for path in sides.values():
            warm(path)
        seconds = {k: [] for k in sides}
        worst, split = {}, {}
        for r in range(args.repeats):
            for key, path in sides.items():
                s, predicted = end_to_end(path, Path(tmp) / f"{key}{r}")
                seconds[key].append(s)
                worst[key] = _worst(predicted)
                split[key] = predicted["optimiser"]["seconds"]
        base, now = (statistics.median(seconds[k]) for k in ("baseline", "now"))
        print(
            f"reflector-opt optimise --no-report (defaults), end to end, median of "
            f"{args.repeats}: baseline {args.baseline} {base:.1f} s, now {now:.1f} s "
            f"({base / now:.2f}× faster)"
        )
        print(
            "  result (worst-case 1σ resolution, °): "
            f"baseline {worst['baseline']}, now {worst['now']}"
        )
        print(
            "  of the last run, as design.json records them: "
            + "; ".join(
                f"{key} " + ", ".join(f"{k} {v:.2f} s" for k, v in split[key].items())
                for key in sides
            )
            + " (the rest: start-up, the default design's evaluation, writing)"
        )

    fixed = start_up()
    print(
        f"start-up in a fresh process, median of 3: imports {fixed['imports']:.2f} s, first "
        f"evaluation (the compiled kernels loaded) {fixed['first']:.2f} s"
    )
    times = {}
    for workers in (1, 2):
        b = dataclasses.replace(budget, workers=workers)
        times[workers] = optimise(problem, seed=0, budget=b).seconds["search"]
    print(
        f"search alone: 1 worker {times[1]:.1f} s, 2 workers {times[2]:.1f} s "
        f"(speed-up {times[1] / times[2]:.2f}×)"
    )
    starts, seconds, designs = 4, {}, {}
    for workers in (1, 2, 4):
        t0 = time.perf_counter()
        result = optimise(
            problem, seed=0, budget=budget, starts=starts, executor=local_processes(workers)
        )
        seconds[workers] = time.perf_counter() - t0
        designs[workers] = result.evaluation.values
    same = all(d == designs[1] for d in designs.values())
    print(
        f"multi-start ({starts} starts, spawned local processes), end to end in process: "
        + ", ".join(f"{w} worker(s) {t:.1f} s ({seconds[1] / t:.2f}×)" for w, t in seconds.items())
        + f"; the same design from each: {same}"
    )
    print(f"after: {load()}")


if __name__ == "__main__":
    main()
