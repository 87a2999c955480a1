"""Benchmark of the tolerance study (target: 1,000 samples, 0.5° calibration grid, ≤ 60 s on
two local processes).

Run from the repository root:

    python benchmarks/bench_tolerance.py [--samples 1000]

Prints:
* the cost of one sample in this process (build, metrics on the 1° grid, calibration on the
  0.5° grid: 3,721 poses, validation on 2,000 poses), single-threaded BLAS as in the workers,
  and of one Sobol AB row (the calibrated error alone: no metrics, no misfit fit);
* the units the command's defaults with ``--samples`` simulate: the sample, the
  one-at-a-time runs, the Sobol rows of A and B the sample does not hold, the AB rows;
* the Monte Carlo study of the default design with the default tolerances on two local
  processes (wall time, throughput, yield);
* its throughput on a Dask LocalCluster (loopback) with one and with two single-threaded
  worker processes, and their ratio (the scaling on this machine); and that the results equal
  the local run's;
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
# One BLAS thread in this process too (before numpy loads), as in the workers.
for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")


def load():
    return "load average {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def one_sample(design, repeats=20):
    from reflector_opt.tolerance import Job, Tolerances, draw_sample
    from reflector_opt.tolerance._analysis import evaluate_draws

    job = Job(design)
    draws = [draw_sample(Tolerances(), 2, 0, i) for i in range(repeats + 1)]
    evaluate_draws(job, draws[:1])
    start = time.perf_counter()
    evaluate_draws(job, draws[1:])
    return (time.perf_counter() - start) / repeats


def one_sensitivity_row(design, repeats=20):
    from reflector_opt.tolerance import Job, Tolerances, draw_sample
    from reflector_opt.tolerance._analysis import evaluate_draws

    job = Job(design, full=False)
    draws = [draw_sample(Tolerances(), 2, 0, i) for i in range(repeats + 1)]
    evaluate_draws(job, draws[:1])
    start = time.perf_counter()
    evaluate_draws(job, draws[1:])
    return (time.perf_counter() - start) / repeats


def units_of_the_command(design, samples):
    """Units simulated by ``tolerance --samples N`` with the default config, by part."""
    from reflector_opt.tolerance._config import ToleranceConfig
    from reflector_opt.tolerance._study import _StudyPlan

    config = ToleranceConfig()
    run = config.run
    plan = _StudyPlan(
        design, config.tolerances, config.settings, samples, 0, run.oat_samples, run.sobol_samples
    )
    counts = {}
    for key, (job, draws) in plan.parts.items():
        kind = {"main": "sample", "nominal": "nominal", "sobol:rows": "Sobol A/B rows"}.get(
            key, "one-at-a-time" if job.full else "Sobol AB rows (calibrated error only)"
        )
        counts[kind] = counts.get(kind, 0) + len(draws)
    return counts


def study(design, samples, factory):
    from reflector_opt.tolerance import run_study

    start = time.perf_counter()
    result = run_study(design, samples=samples, seed=0, factory=factory)
    return time.perf_counter() - start, result


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--samples", type=int, default=1000)
    parser.add_argument("--dask-samples", type=int, default=256)
    args = parser.parse_args()

    from distributed import LocalCluster

    from reflector_opt import default_design
    from reflector_opt.tolerance import dask_cluster
    from reflector_opt.util._pools import local_processes

    design = default_design()
    print(load(), "(before)")
    full, row = one_sample(design), one_sensitivity_row(design)
    print(f"one sample in this process: {1e3 * full:.1f} ms; one Sobol AB row {1e3 * row:.1f} ms")
    counts = units_of_the_command(design, args.samples)
    print(
        f"tolerance --samples {args.samples} simulates {sum(counts.values())} units: "
        + ", ".join(f"{n} {kind}" for kind, n in counts.items())
    )

    seconds, local = study(design, args.samples, local_processes(2))
    y = local.summary["yield"]
    print(
        f"{args.samples} samples, 2 local processes: {seconds:.1f} s "
        f"({args.samples / seconds:.1f} samples/s); yield {100 * y['all']:.1f} %"
    )

    rates = {}
    for workers in (1, 2):
        with LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            host="127.0.0.1",
        ) as cluster:
            factory = dask_cluster(cluster.scheduler_address)
            study(design, 32, factory)  # workers import the package and warm up
            seconds, result = study(design, args.dask_samples, factory)
        rates[workers] = args.dask_samples / seconds
        same = result.records == local.records[: args.dask_samples]
        print(
            f"Dask, {workers} worker(s): {args.dask_samples} samples in {seconds:.1f} s "
            f"({rates[workers]:.1f} samples/s); equal to the local run: {same}"
        )
    print(f"Dask scaling 1 -> 2 workers: {rates[2] / rates[1]:.2f}x")
    print(load(), "(after)")


if __name__ == "__main__":
    main()
