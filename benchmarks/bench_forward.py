"""Benchmark: the full forward model on the paper's calibration grid, against the previous model.

±15° pitch and roll in 0.1° steps (301 × 301 = 90,601 poses), two sensors; distance (Eq 3),
optical coupling (the surface model) and output voltage of the default design. In one run:

* :func:`~reflector_opt.model._forward.respond` as the forward model computes it: one compiled
  geometry pass over every pose, the surface couplings at the 7 × 7 Chebyshev points of the
  workspace and their interpolation to every pose; on the grid (pitch column × roll row) and
  on the same poses as flat arrays, and ``voltages`` alone;
* :func:`reflector_opt.model._reference.direct_response`, which computes the surface
  couplings at every pose (no interpolation), and the largest difference of the two;
* the previous model, commit ``--baseline-commit`` (default ``c69f632``, the paraxial
  Gaussian-spot coupling), from a temporary ``git worktree`` of that commit, against the
  current one: both timed by the same code (full-grid ``respond``, best of ``--repeat``) in
  fresh subprocesses that each import their own checkout, alternately for ``--rounds``
  rounds. The ratio of the two best times is the slowdown (target: at most 1.5×); the
  per-round ratios show how much the machine's load moves it.

Compilation happens before the timing (first call). The compiled coupling loop runs on
numba's threads (``NUMBA_NUM_THREADS``, all cores by default), which ``OMP_NUM_THREADS``
does not limit; set both to 1 for a one-core figure.

Run from the repository root:

    OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1 python benchmarks/bench_forward.py [--repeat N]
"""

import argparse
import os
import platform
import subprocess
import sys
import timeit
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numba  # noqa: E402
import numpy as np  # noqa: E402
from baseline import checkout, run_script  # noqa: E402

import reflector_opt as ro  # noqa: E402
from reflector_opt.model._reference import direct_response  # noqa: E402

#: The full-grid timing, run in the checkout of another commit (its own package imported).
TIMING = """
import json, sys, timeit
import reflector_opt as ro
design = ro.default_design()
pitch, roll = design.workspace.grid()
ro.respond(design, pitch, roll)
repeat = int(sys.argv[1])
t = min(timeit.repeat(lambda: ro.respond(design, pitch, roll), number=1, repeat=repeat))
print(json.dumps({"respond_ms": 1e3 * t, "package": ro.__file__}))
"""


def processor():
    """The CPU's model name (Linux), else what :mod:`platform` says."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def best_ms(function, repeat):
    """Best of ``repeat`` timings of one call, in milliseconds."""
    return 1e3 * min(timeit.repeat(function, number=1, repeat=repeat))


def checkout_ms(tree, repeat):
    """Best full-grid ``respond`` time of the package in ``tree``, ms (a subprocess)."""
    return run_script(tree, TIMING, repeat)["respond_ms"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=20, help="timings per figure (best)")
    parser.add_argument("--rounds", type=int, default=5, help="alternate rounds new/previous")
    parser.add_argument("--baseline-commit", default="c69f632", help="'' to skip")
    args = parser.parse_args()

    design = ro.default_design()
    pitch, roll = design.workspace.grid()  # (301, 1) and (1, 301)
    flat_pitch, flat_roll = (a.ravel() for a in np.broadcast_arrays(pitch, roll))
    n_poses = flat_pitch.size

    fast = ro.respond(design, pitch, roll)
    t0 = timeit.default_timer()
    distance, coupling, volts = direct_response(design, pitch, roll)
    t_direct = 1e3 * (timeit.default_timer() - t0)
    assert np.allclose(fast.distance_mm, distance, rtol=0.0, atol=1e-12)
    coupling_error = float(np.max(np.abs(fast.coupling / coupling - 1.0)))
    volts_error = float(np.max(np.abs(fast.volts - volts)))

    t_grid = best_ms(lambda: ro.respond(design, pitch, roll), args.repeat)
    t_flat = best_ms(lambda: ro.respond(design, flat_pitch, flat_roll), args.repeat)
    t_volts = best_ms(lambda: ro.voltages(design, pitch, roll), args.repeat)

    previous, current = [], []
    if args.baseline_commit:
        with checkout(args.baseline_commit) as baseline:
            for _ in range(args.rounds):
                previous.append(checkout_ms(baseline, args.repeat))
                current.append(checkout_ms(ROOT, args.repeat))

    head = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
    ).stdout.strip()
    print(f"poses: {n_poses} x 2 sensors; numpy {np.__version__}; {processor()}")
    print(f"current model: {head or 'unknown'} (working tree); previous: {args.baseline_commit}")
    print(
        f"OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS', 'unset')}, numba threads "
        f"{numba.get_num_threads()}; best of {args.repeat}; load average "
        + " ".join(f"{v:.2f}" for v in os.getloadavg())
    )
    print(f"respond (grid, pitch x roll broadcast): {t_grid:9.2f} ms")
    print(f"respond (flat pose arrays):             {t_flat:9.2f} ms")
    print(f"voltages only (grid):                   {t_volts:9.2f} ms")
    print(f"direct, couplings at every pose (once): {t_direct:9.0f} ms")
    print(f"speed-up, grid vs direct:               {t_direct / t_grid:9.0f} x")
    print(f"largest difference from direct:         {coupling_error:9.1e} (coupling, relative)")
    print(f"                                        {volts_error:9.1e} V")
    if previous:
        print(f"full-grid respond in fresh processes, {args.rounds} alternate rounds (ms):")
        ratios = [c / p for c, p in zip(current, previous, strict=True)]
        for label, values in (
            (f"previous model ({args.baseline_commit})", previous),
            ("current model", current),
            ("ratio, current / previous", ratios),
        ):
            print(f"  {label:<28} " + ", ".join(f"{v:.2f}" for v in values))
        print(
            f"ratio of the best times, current / previous: {min(current):.2f} / "
            f"{min(previous):.2f} ms = {min(current) / min(previous):.2f} x (target ≤ 1.5)"
        )


if __name__ == "__main__":
    main()
