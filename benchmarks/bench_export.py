"""Benchmark: ``reflector-opt export`` of the optimised design, against a baseline commit.

Times, for the design ``optimise`` returns by default (``tests/cad/data/optimised_design.json``,
from ``python -m reflector_opt optimise --no-report``) at the default 0.01 mm chord tolerance:

* the stages of one export — layout, solids, meshes, collision check, printability, Eq 3
  ray check, writers, previews — in this working tree and in a checkout of the baseline
  commit (today's code path, kept as the reference), each in a fresh interpreter;
* candidates for the gap between the posed reflector and the fixed solids at one pose:
  manifold3d's ``min_gap`` (the baseline's), coal's BVH distance on the meshes;
* the end-to-end CLI, ``export --part all --no-preview`` and ``export --part all``, run
  alternately for the baseline and this tree, so that the speed-up is a ratio measured in
  one run on a machine shared with other work.

Targets: ``--part all --no-preview`` at least 5x faster than the baseline; ``--part all``
with previews under 4 s.

Run:  OMP_NUM_THREADS=1 python benchmarks/bench_export.py [--repeat 3] [--commit 7dc9dbd]
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

from baseline import ROOT, checkout, run_script

DESIGN = ROOT / "tests" / "cad" / "data" / "optimised_design.json"

SCRIPT = (ROOT / "benchmarks" / "export_stages.py").read_text()


def cli_seconds(tree, *args):
    """Wall time of one ``python -m reflector_opt export`` with ``tree``'s package."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    with tempfile.TemporaryDirectory() as out:
        command = [sys.executable, "-m", "reflector_opt", "export", str(DESIGN), "-o", out]
        t = time.perf_counter()
        subprocess.run([*command, *args], cwd=tree, env=env, check=True, capture_output=True)
        return time.perf_counter() - t


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--commit", default="7dc9dbd")
    args = parser.parse_args()
    print(f"load average {os.getloadavg()}; {os.cpu_count()} cores")
    print(f"OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS', 'unset')}; design {DESIGN.name}")
    with checkout(args.commit) as base:
        trees = {f"baseline {args.commit}": base, "this tree": ROOT}
        # One export each first: numba compiles the model into each tree's cache.
        for tree in trees.values():
            cli_seconds(tree, "--part", "reflector", "--no-preview")
        stages = {name: run_script(tree, SCRIPT, DESIGN, "stages") for name, tree in trees.items()}
        print("\nstages of one export (s), fresh interpreter each:")
        rows = list(dict.fromkeys(k for s in stages.values() for k in s["times"]))
        print(f"  {'stage':22s}" + "".join(f"{n:>22s}" for n in stages))
        for row in rows:
            cells = "".join(f"{s['times'].get(row, float('nan')):22.2f}" for s in stages.values())
            print(f"  {row:22s}{cells}")
        for name, s in stages.items():
            print(f"  {name}: triangles {s['triangles']}; collision {s['collision']}")

        gaps = run_script(ROOT, SCRIPT, DESIGN, "gaps")
        del gaps["package"]
        print("\ngap between the posed reflector and the fixed solids at one pose:")
        for key, value in gaps.items():
            print(f"  {key:40s} {value:8.3f}")

        print(f"\nend-to-end CLI, alternating, {args.repeat} runs each (median, best):")
        for options in (("--part", "all", "--no-preview"), ("--part", "all")):
            seconds = {name: [] for name in trees}
            for _ in range(args.repeat):
                for name, tree in trees.items():
                    seconds[name].append(cli_seconds(tree, *options))
            for name, values in seconds.items():
                print(
                    f"  export {' '.join(options):24s} {name:20s} "
                    f"{statistics.median(values):6.2f} s  {min(values):6.2f} s"
                )
            base_s, new_s = (statistics.median(v) for v in seconds.values())
            print(f"  speed-up (median): {base_s / new_s:.1f}x")
    print(f"load average {os.getloadavg()}")


if __name__ == "__main__":
    main()
