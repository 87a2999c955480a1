"""Benchmark of ``reflector-opt optimise`` (targets: ≤ 60 s end to end, search ≤ 20 s).

Run from the repository root:

    python benchmarks/bench_optimise.py

Prints, for the built-in defaults:
* the wall time of the command end to end (a fresh ``python -m reflector_opt optimise``
  process: start-up, imports, search, polish, verification, baseline, writing design.json);
* the stages of one in-process run and its model evaluations;
* the cost of one model evaluation on the search grid, and the search with one and with two
  worker processes (their ratio is the parallel speed-up on this machine);
* the machine's load average, since the cores are shared.
"""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from reflector_opt.optimise import Problem, SearchBudget, optimise  # noqa: E402
from reflector_opt.optimise.evaluation import PenalisedObjective  # noqa: E402


def load():
    return "load average {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def end_to_end():
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "reflector_opt", "optimise", "--out", out, "--quiet"],
            cwd=ROOT,
            check=True,
            capture_output=True,
        )
        return time.perf_counter() - t0


def evaluation_cost(problem, budget, x, repeats=200):
    objective = PenalisedObjective(problem, budget.grid_step_deg)
    objective(x)
    t0 = time.perf_counter()
    for _ in range(repeats):
        objective(x)
    return (time.perf_counter() - t0) / repeats


def main():
    print(f"{os.cpu_count()} cores, {load()}")
    wall = end_to_end()
    print(f"reflector-opt optimise (defaults), end to end: {wall:.1f} s  (target ≤ 60 s)")

    problem, budget = Problem(), SearchBudget()
    result = optimise(problem, seed=0, budget=budget)
    s, n = result.seconds, result.evaluations
    print(
        f"in-process run: search {s['search']:.1f} s (target ≤ 20 s), "
        f"polish + verification {s['polish_and_verify']:.1f} s"
    )
    stages = ", ".join(f"{k} {v}" for k, v in n.items())
    print(
        f"model evaluations: {stages} (total {sum(n.values())}); {len(result.history)} generations"
    )
    m = result.metrics
    print(
        f"result: worst-case resolution pitch {m.worst_pitch_deg:.4f}°, roll "
        f"{m.worst_roll_deg:.4f}°, improvement over the default design "
        f"{result.improvement['worst']:.2f}×"
    )

    x = np.array([result.evaluation.values[name] for name in problem.free_names])
    per_eval = evaluation_cost(problem, budget, x)
    poses = len(problem.workspace.axes(budget.grid_step_deg)[0]) ** 2
    print(
        f"one evaluation on the {budget.grid_step_deg}° search grid ({poses} poses, 5-point "
        f"stencil): {per_eval * 1e3:.2f} ms"
    )
    times = {}
    for workers in (1, 2):
        b = dataclasses.replace(budget, workers=workers)
        times[workers] = optimise(problem, seed=0, budget=b).seconds["search"]
    print(
        f"search alone: 1 worker {times[1]:.1f} s, 2 workers {times[2]:.1f} s "
        f"(speed-up {times[1] / times[2]:.2f}×)"
    )
    print(f"after: {load()}")


if __name__ == "__main__":
    main()
