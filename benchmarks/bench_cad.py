"""Benchmark: export of the reflector part at the default 0.01 mm chord tolerance.

Times :func:`reflector_opt.cad.export_parts` for the reflector alone (layout, both solids,
the collision check over the workspace, the printability report, the Eq 3 ray check, STL, 3MF
and PNG) and, in the same run, at 0.02 and 0.05 mm for the ratio; then the stages of one
0.01 mm export. Target: ≤ 5 s and an STL under 20 MB.

The default design cannot be printed (its shell is 0.74 mm at the top of the band, below the
0.8 mm minimum), so the benchmark uses the printable variant with the sphere's centre 1.2 mm
below O instead of 1.5 mm (docs/cad.md).

Run:  OMP_NUM_THREADS=1 python benchmarks/bench_cad.py [--repeat N]
"""

import argparse
import os
import platform
import tempfile
import time
import timeit

from reflector_opt.cad import (
    build_parts,
    check_collisions,
    check_printability,
    export_parts,
    plan_layout,
    to_trimesh,
    verify_distances,
)
from reflector_opt.design import Reflector, default_design


def best_s(function, repeat):
    """Best of ``repeat`` timings of one call, in seconds."""
    return min(timeit.repeat(function, number=1, repeat=repeat))


def stages(design, tolerance):
    """Wall time of each stage of one export, seconds."""
    times = {}
    t = time.perf_counter()
    layout = plan_layout(design)
    times["layout"] = time.perf_counter() - t
    t = time.perf_counter()
    parts = build_parts(design, layout, tolerance)
    meshes = {name: to_trimesh(getattr(parts, name)) for name in ("reflector", "body")}
    times["solids (manifold3d booleans)"] = time.perf_counter() - t
    t = time.perf_counter()
    collision = check_collisions(parts, design)
    times["collision check"] = time.perf_counter() - t
    t = time.perf_counter()
    check_printability(
        "reflector", parts.reflector, meshes["reflector"], layout, tolerance, collision
    )
    times["printability report"] = time.perf_counter() - t
    t = time.perf_counter()
    verify_distances(meshes["reflector"], design, tolerance)
    times["Eq 3 ray check, 98 rays"] = time.perf_counter() - t
    return times


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    repeat = parser.parse_args().repeat
    design = default_design().replace(reflector=Reflector(9.0, (0.0, 0.0, -1.2), 7.5))

    print(f"{platform.processor() or platform.machine()}; load average {os.getloadavg()}")
    print(f"OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS', 'unset')}; best of {repeat}")
    results = {}
    with tempfile.TemporaryDirectory() as out:
        for tolerance in (0.05, 0.02, 0.01):
            report = export_parts(design, out, parts=("reflector",), tolerance_mm=tolerance)
            seconds = best_s(
                lambda t=tolerance: export_parts(design, out, parts=("reflector",), tolerance_mm=t),
                repeat,
            )
            seconds_np = best_s(
                lambda t=tolerance: export_parts(
                    design, out, parts=("reflector",), tolerance_mm=t, preview=False
                ),
                repeat,
            )
            results[tolerance] = (seconds, seconds_np, report)
    print("tolerance  export  (no PNG)  triangles   STL       3MF      ray-check max error")
    for tolerance, (seconds, seconds_np, report) in results.items():
        entry = report["files"]["reflector"]
        print(
            f"{tolerance:7.2f} mm {seconds:6.2f} s {seconds_np:6.2f} s {entry['triangles']:9d} "
            f"{entry['stl_bytes'] / 1e6:6.3f} MB {entry['3mf_bytes'] / 1e6:6.3f} MB "
            f"{report['ray_check']['max_error_mm']:.4f} mm"
        )
    base = results[0.05][0]
    print(
        "time ratio to 0.05 mm: "
        + ", ".join(f"{t:g} mm {v[0] / base:.2f}x" for t, v in results.items())
    )
    print("stages of one 0.01 mm export (reflector; both solids are built for the check):")
    for stage, seconds in stages(design, 0.01).items():
        print(f"  {stage:32s} {seconds:6.2f} s")


if __name__ == "__main__":
    main()
