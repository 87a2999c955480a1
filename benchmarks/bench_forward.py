"""Benchmark: the full forward model on the paper's calibration grid.

±15° pitch and roll in 0.1° steps (301 × 301 = 90,601 poses), two sensors; distance (Eq 3),
optical coupling (Eq 4 extended) and output voltage. Compares, in the same run,
:func:`~reflector_opt.model.forward.respond` (one compiled pass, :mod:`~.kernel`) with
the straightforward formulation that builds a 3×3 rotation matrix per pose
(:func:`reflector_opt.model.reference.direct_response`), and also times the separable grid against
the same poses given as flat arrays. Compilation happens before the timing (first call).

Run:  OMP_NUM_THREADS=1 python benchmarks/bench_forward.py [--repeat N]
"""

import argparse
import os
import platform
import timeit

import numpy as np

import reflector_opt as ro
from reflector_opt.model.reference import direct_response


def best_ms(function, repeat):
    """Best of ``repeat`` timings of one call, in milliseconds."""
    return 1e3 * min(timeit.repeat(function, number=1, repeat=repeat))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=20)
    repeat = parser.parse_args().repeat

    design = ro.default_design()
    pitch, roll = design.workspace.grid()  # (301, 1) and (1, 301)
    flat_pitch, flat_roll = (a.ravel() for a in np.broadcast_arrays(pitch, roll))
    n_poses = flat_pitch.size

    fast = ro.respond(design, pitch, roll)
    distance, _, volts = direct_response(design, pitch, roll)
    assert np.allclose(fast.volts, volts, atol=1e-12) and np.allclose(fast.distance_mm, distance)

    t_grid = best_ms(lambda: ro.respond(design, pitch, roll), repeat)
    t_flat = best_ms(lambda: ro.respond(design, flat_pitch, flat_roll), repeat)
    t_volts = best_ms(lambda: ro.voltages(design, pitch, roll), repeat)
    t_direct = best_ms(lambda: direct_response(design, pitch, roll), max(3, repeat // 4))

    print(f"poses: {n_poses} x 2 sensors; numpy {np.__version__}; {platform.processor()}")
    print(f"OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS', 'unset')}; best of {repeat}")
    print(f"respond (grid, pitch x roll broadcast): {t_grid:8.2f} ms")
    print(f"respond (flat pose arrays):             {t_flat:8.2f} ms")
    print(f"voltages only (grid):                   {t_volts:8.2f} ms")
    print(f"direct, 3x3 matrix per pose:            {t_direct:8.2f} ms")
    print(f"speed-up, grid vs direct:               {t_direct / t_grid:8.1f} x")
    print(f"speed-up, flat vs direct:               {t_direct / t_flat:8.1f} x")


if __name__ == "__main__":
    main()
