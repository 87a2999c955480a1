"""Record what the export at a baseline commit writes, for the geometry test of today's export.

Runs the baseline's own ``export_parts`` (``--part reflector`` and ``body``, no preview) on
the optimised design in ``tests/cad/data/optimised_design.json`` in a checkout of the
baseline commit, and stores, for each written STL: its volume and area, points sampled on
its surface (seeded), and the hit distance of each Eq 3 ray; the test
``tests/cad/test_export_geometry.py`` holds today's export to them.

Run:  python benchmarks/export_reference.py [--commit 7dc9dbd]
"""

import argparse
import sys

from baseline import ROOT, checkout, run_script

DESIGN = ROOT / "tests" / "cad" / "data" / "optimised_design.json"
OUT = ROOT / "tests" / "cad" / "data" / "export_7dc9dbd.npz"

SCRIPT = r"""
import json, sys, tempfile
import numpy as np, trimesh
import reflector_opt
from reflector_opt.cad import export_parts
from reflector_opt.design import load_design

design = load_design(sys.argv[1])
arrays = {}
with tempfile.TemporaryDirectory() as out:
    export_parts(design, out, parts=("reflector", "body"), preview=False)
    for name in ("reflector", "body"):
        mesh = trimesh.load(f"{out}/{name}.stl")
        points, _ = trimesh.sample.sample_surface(mesh, 4000, seed=0)
        arrays[f"{name}_points"] = points
        arrays[f"{name}_volume"] = mesh.volume
        arrays[f"{name}_area"] = mesh.area
        if name == "reflector":
            from reflector_opt.cad._verification import verification_poses
            from reflector_opt.model._geometry import rotation_x, rotation_y
            pitch, roll = verification_poses(design)
            f = design.positions_mm
            s0 = np.asarray(design.reflector.centre_mm)
            rot = rotation_x(roll) @ rotation_y(pitch)
            origins = np.einsum("pji,sj->psi", rot, f).reshape(-1, 3)
            directions = s0 - origins
            directions /= np.linalg.norm(directions, axis=1, keepdims=True)
            hits, index, _ = mesh.ray.intersects_location(origins, directions, multiple_hits=False)
            distance = np.full(len(origins), np.nan)
            distance[index] = np.einsum("ij,ij->i", hits - origins[index], directions[index])
            arrays["ray_distance"] = distance
np.savez_compressed(sys.argv[2], **arrays)
print(json.dumps({"package": reflector_opt.__file__}))
"""


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--commit", default="7dc9dbd")
    args = parser.parse_args()
    with checkout(args.commit) as tree:
        run_script(tree, SCRIPT, DESIGN, OUT)
    print(f"wrote {OUT}", file=sys.stderr)


if __name__ == "__main__":
    main()
