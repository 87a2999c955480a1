"""Benchmark: start-up time of the package and of the command line's help.

Times, in fresh interpreters, ``import reflector_opt``, ``reflector-opt --help`` and every
``reflector-opt SUBCOMMAND --help`` (wall time of the whole process, as a user waits for
it), with the bare interpreter (``python -c pass``) and NumPy's import for reference. The
same commands run against a baseline commit checked out in a temporary ``git worktree`` (by
default ``7dc9dbd``, before the imports were made lazy), alternating baseline and current in
every round, so the ratio is measured under the same load. Each figure is the median over
the rounds. Target: every command under 0.5 s.

Run:  python benchmarks/bench_startup.py [--rounds N] [--baseline COMMIT] [--current COMMIT]
"""

import argparse
import os
import platform
import resource
import statistics
import subprocess
import sys
import time
from contextlib import contextmanager
from pathlib import Path

from baseline import ROOT, checkout

SUBCOMMANDS = (
    "evaluate",
    "optimise",
    "fit-sensor",
    "calibrate",
    "estimate",
    "export",
    "report",
    "tolerance",
    "sweep",
)
COMMANDS = {
    "python -c pass": ["-c", "pass"],
    "python -c 'import numpy'": ["-c", "import numpy"],
    "import reflector_opt": ["-c", "import reflector_opt"],
    "reflector-opt --help": ["-m", "reflector_opt", "--help"],
    **{f"reflector-opt {s} --help": ["-m", "reflector_opt", s, "--help"] for s in SUBCOMMANDS},
}
TARGET_S = 0.5


def run_s(tree, argv):
    """Wall and CPU time (user + system) of one fresh interpreter running ``argv``, s.

    The CPU time is what the process itself spent; on a machine busy with other work the wall
    time grows with the wait for a core while the CPU time stays close to the idle wall time.
    """
    env = {**os.environ, "PYTHONPATH": str(tree)}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    subprocess.run([sys.executable, *argv], cwd=tree, env=env, capture_output=True, check=True)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def check_package(tree):
    """Refuse to time a tree whose interpreter would import another copy of the package."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    found = subprocess.run(
        [sys.executable, "-c", "import reflector_opt; print(reflector_opt.__file__)"],
        cwd=tree,
        env=env,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    if not Path(found).resolve().is_relative_to(Path(tree).resolve()):
        raise RuntimeError(f"{tree} imports {found}")


@contextmanager
def current_tree(commit):
    """The working tree, or a temporary checkout of ``commit``."""
    if commit is None:
        yield ROOT
    else:
        with checkout(commit) as tree:
            yield tree


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7, help="fresh processes per command (7)")
    parser.add_argument("--baseline", default="7dc9dbd", help="commit to compare with")
    parser.add_argument("--current", help="time this commit instead of the working tree")
    args = parser.parse_args()
    print(
        f"Python {platform.python_version()}, {os.cpu_count()} cores, "
        f"load average {os.getloadavg()[0]:.2f} at start; {args.rounds} rounds, median"
    )
    with checkout(args.baseline) as old, current_tree(args.current) as new:
        trees = {"baseline": old, "current": new}
        for tree in trees.values():
            check_package(tree)
            for argv in COMMANDS.values():  # warm the file cache
                run_s(tree, argv)
        times = {(name, label): [] for name in COMMANDS for label in trees}
        for _ in range(args.rounds):
            for name, argv in COMMANDS.items():
                for label, tree in trees.items():
                    times[name, label].append(run_s(tree, argv))
    print(f"load average {os.getloadavg()[0]:.2f} at the end")
    print(
        f"{'command':<34}{'baseline wall':>14}{'current wall':>13}{'ratio':>7}"
        f"{'baseline CPU':>13}{'current CPU':>12}  target (wall)"
    )
    worst = 0.0
    for name in COMMANDS:
        old_wall, old_cpu = (
            statistics.median(x) for x in zip(*times[name, "baseline"], strict=True)
        )
        new_wall, new_cpu = (
            statistics.median(x) for x in zip(*times[name, "current"], strict=True)
        )
        reference = name.startswith("python")
        verdict = "" if reference else ("met" if new_wall < TARGET_S else "MISSED")
        if verdict:
            worst = max(worst, new_wall)
        print(
            f"{name:<34}{old_wall:>13.3f}s{new_wall:>12.3f}s{new_wall / old_wall:>6.2f}×"
            f"{old_cpu:>12.3f}s{new_cpu:>11.3f}s  {verdict}"
        )
    print(f"slowest current command: {worst:.3f} s wall (target < {TARGET_S} s)")


if __name__ == "__main__":
    main()
