"""Benchmark of the robust optimisation and of the yield beside the Pareto front.

Run from the repository root:

    python benchmarks/bench_robust.py [--tolerances examples/tolerance.toml] [--yield-samples 1000]

Prints, for the default optimiser problem and budget and the tolerance model given (default:
the built-in tolerances, 500 units per study, seed 0, two local processes):

* each round of :func:`reflector_opt.optimiser._robust.robust_optimise`: the margin the
  optimiser had to meet, the margin it reached, the margin the tolerances take in 99 % of the
  built units (95 % upper confidence bound, and the sample quantile of the units sampled),
  the window yield with its 95 % interval, the resolution; the wall time of
  the loop and of the plain optimisation (its first round) for comparison;
* the yield against every target (window, calibrated RMS and maximum error) of the ordinary
  and of the robust design, from a calibrated study of ``--yield-samples`` units each, drawn
  with the next seed (units the loop has not seen), and the time of one such study;
* the window yield of the robust design on ``--coverage-samples`` fresh units (geometry
  only, next seed): how well the coverage measured on the loop's own units holds on others;
* the machine's load average before and after, since the cores are shared.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def load():
    return "load average {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def yield_line(name, study):
    s = study.summary
    low, high = s["yield_interval"]["all"]
    y = s["yield"]
    return (
        f"{name}: yield {100 * y['all']:.1f} % [{100 * low:.1f}–{100 * high:.1f} %] "
        f"(window {100 * y['window']:.1f} %, RMS {100 * y['rms']:.1f} %, "
        f"max {100 * y['max']:.1f} %) of {s['samples']} units"
    )


def main():
    from dataclasses import replace

    from reflector_opt.optimiser import Problem
    from reflector_opt.optimiser._robust import robust_optimise, tolerance_study
    from reflector_opt.tolerance._config import ToleranceConfig, load_tolerance_config
    from reflector_opt.util._pools import local_processes, reused

    parser = argparse.ArgumentParser()
    parser.add_argument("--tolerances", help="a tolerance config (default: built-in)")
    parser.add_argument("--yield-samples", type=int, default=1000)
    parser.add_argument("--coverage-samples", type=int, default=4000)
    args = parser.parse_args()
    tolerance = load_tolerance_config(args.tolerances) if args.tolerances else ToleranceConfig()
    print(load())
    problem = Problem()
    with reused(local_processes(tolerance.run.workers)) as factory:
        start = time.perf_counter()
        robust = robust_optimise(problem, tolerance, seed=0, factory=factory)
        seconds = time.perf_counter() - start
        print(
            f"robust optimisation: {len(robust.rounds)} round(s), converged {robust.converged}, "
            f"{seconds:.1f} s ({tolerance.run.samples} units per study, coverage "
            f"{robust.options.coverage:g})"
        )
        for r in robust.rounds:
            low, high = r["window_yield_interval"]
            print(
                f"  round {r['round']}: limit {r['limit_mm']:.4f} mm, margin "
                f"{r['margin_mm']:.4f} mm, required {r['required_mm']:.4f} mm (sample quantile "
                f"{r['required_estimate_mm']:.4f} mm), window yield "
                f"{100 * r['window_yield']:.1f} % [{100 * low:.1f}–{100 * high:.1f} %], "
                f"resolution {r['objective_deg']:.4f}°"
            )
        optimiser = robust.design.predicted["optimiser"]
        print(f"  last round's optimisation: {sum(optimiser['seconds'].values()):.1f} s")

        # another run seed: its streams (util.seeds) are independent of the study's own draws
        fresh = replace(tolerance.run, samples=args.yield_samples, seed=tolerance.run.seed + 1)
        check = replace(tolerance, run=fresh)
        ordinary = problem.design(robust.rounds[0]["variables"])
        start = time.perf_counter()
        before = tolerance_study(ordinary, check, factory, calibrate=True)
        study_seconds = time.perf_counter() - start
        after = tolerance_study(robust.design, check, factory, calibrate=True)
        wide = replace(tolerance, run=replace(fresh, samples=args.coverage_samples))
        start = time.perf_counter()
        geometry = tolerance_study(robust.design, wide, factory, calibrate=False).summary
        geometry_seconds = time.perf_counter() - start
    print(yield_line("ordinary optimum", before))
    print(yield_line("robust design", after))
    print(f"one calibrated study of {args.yield_samples} units: {study_seconds:.1f} s")
    low, high = geometry["yield_interval"]["window"]
    print(
        f"robust design, {args.coverage_samples} fresh units, geometry only: window kept "
        f"{100 * geometry['yield']['window']:.2f} % [{100 * low:.2f}–{100 * high:.2f} %]; "
        f"their own {100 * robust.options.coverage:g} % quantile of the lost margin "
        f"{geometry['required_margin_mm']['estimate']:.4f} mm; {geometry_seconds:.1f} s"
    )
    print(load())


if __name__ == "__main__":
    main()
