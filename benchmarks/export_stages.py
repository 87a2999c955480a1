"""Timing script of ``bench_export.py``, run by it in a fresh interpreter against one tree.

``python export_stages.py DESIGN stages`` times the stages of one export with the package
it imports (this tree's or a baseline checkout's); ``... gaps`` times the candidates for the
gap between the posed reflector and the fixed solids. Prints one JSON object.
"""

import inspect
import json
import sys
import tempfile
import time

T0 = time.perf_counter()
import numpy as np  # noqa: E402

import reflector_opt  # noqa: E402
from reflector_opt.cad import (  # noqa: E402
    build_parts,
    check_collisions,
    check_printability,
    plan_layout,
    to_trimesh,
    verify_distances,
)
from reflector_opt.cad._meshfiles import write_3mf, write_stl  # noqa: E402
from reflector_opt.cad._solids import pose, pose_matrix  # noqa: E402
from reflector_opt.design import load_design  # noqa: E402

IMPORTS_S = time.perf_counter() - T0
TOLERANCE = 0.01
ALL_SOLIDS = ("reflector", "inner_ring", "body", "outer_ring", "sensors")


def stages(design):
    """Seconds per stage of one export, and what it found."""
    times = {"imports": IMPORTS_S}

    def timed(name, call):
        t = time.perf_counter()
        out = call()
        times[name] = times.get(name, 0.0) + time.perf_counter() - t
        return out

    layout = timed("layout", lambda: plan_layout(design))
    parts = timed("solids", lambda: build_parts(design, layout, TOLERANCE))
    # The baseline meshed the printed parts only; its collision check used the solids.
    shares = "meshes" in inspect.signature(check_collisions).parameters
    names = ALL_SOLIDS if shares else ("reflector", "body")
    meshes = timed("meshes", lambda: {n: to_trimesh(getattr(parts, n)) for n in names})
    extra = {"meshes": meshes} if shares else {}
    collision = timed("collision", lambda: check_collisions(parts, design, **extra))
    # The baseline's printability took the collision report (to repeat its problem).
    takes = "collision" in inspect.signature(check_printability).parameters
    more = (collision,) if takes else ()
    for name in ("reflector", "body"):
        timed(
            "printability",
            lambda n=name: check_printability(
                n, getattr(parts, n), meshes[n], layout, TOLERANCE, *more
            ),
        )
    timed("ray check", lambda: verify_distances(meshes["reflector"], design, TOLERANCE))
    with tempfile.TemporaryDirectory() as out:
        for name in ("reflector", "body"):
            timed("writers", lambda n=name: write_stl(f"{out}/{n}.stl", meshes[n]))
            timed("writers", lambda n=name: write_3mf(f"{out}/{n}.3mf", {n: meshes[n]}))
        t = time.perf_counter()
        from reflector_opt.cad._preview import render_meshes

        times["preview imports"] = time.perf_counter() - t
        for name in ("reflector", "body"):
            timed(
                "previews (2 parts)",
                lambda n=name: render_meshes(f"{out}/{n}.png", {n: meshes[n]}, n),
            )
    report = collision.to_dict()
    keys = ("poses", "cells", "min_clearance_mm", "worst_pose_deg", "collision_free")
    return {
        "times": times,
        "triangles": {n: len(meshes[n].faces) for n in ("reflector", "body")},
        "collision": {k: report.get(k) for k in keys},
    }


def _bvh(mesh):
    import coal

    model = coal.BVHModelOBBRSS()
    model.beginModel(len(mesh.faces), len(mesh.vertices))
    model.addVertices(np.asarray(mesh.vertices, dtype=float))
    model.addTriangles(np.asarray(mesh.faces, dtype=np.int64))
    model.endModel()
    return model


def gaps(design):
    """Milliseconds per pose of each gap candidate, and how far their gaps differ (mm)."""
    import coal

    parts = build_parts(design, plan_layout(design), TOLERANCE)
    fixed = parts.body + parts.outer_ring + parts.sensors
    poses = [(-15.0, -15.0), (0.0, 0.0), (15.0, 15.0), (7.0, -3.0)]
    t = time.perf_counter()
    by_manifold = [pose(parts.reflector, g, a).min_gap(fixed, 0.5) for g, a in poses]
    manifold_ms = 1e3 * (time.perf_counter() - t) / len(poses)
    t = time.perf_counter()
    moving, still = _bvh(to_trimesh(parts.reflector)), _bvh(to_trimesh(fixed))
    build_ms = 1e3 * (time.perf_counter() - t)
    t = time.perf_counter()
    by_coal = [
        coal.distance(
            moving,
            coal.Transform3s(pose_matrix(g, a)[:, :3], np.zeros(3)),
            still,
            coal.Transform3s(),
            coal.DistanceRequest(),
            coal.DistanceResult(),
        )
        for g, a in poses
    ]
    coal_ms = 1e3 * (time.perf_counter() - t) / len(poses)
    difference = np.abs(np.minimum(by_manifold, 0.5) - np.minimum(by_coal, 0.5)).max()
    return {
        "manifold3d min_gap, ms a pose": manifold_ms,
        "coal BVH build (once), ms": build_ms,
        "coal BVH distance, ms a pose": coal_ms,
        "largest difference of the two gaps, mm": float(difference),
    }


if __name__ == "__main__":
    what = {"stages": stages, "gaps": gaps}[sys.argv[2]]
    result = what(load_design(sys.argv[1]))
    print(json.dumps({"package": reflector_opt.__file__, **result}))
