"""Printable CAD of a design: the reflector part and the unit body as verified STL and 3MF.

Solids are built by constructive solid geometry on exact primitives with manifold3d, meshed
to a chord tolerance, checked for printability (closed, oriented, positive volume, inside
the envelope, walls above the printable minimum, no collision over the workspace) and
verified against the model: rays from the sensors hit the mesh at the Eq 3 distance.
See docs/cad.md.
"""

from reflector_opt.cad.clearance import CollisionReport, check_collisions
from reflector_opt.cad.export import DEFAULT_TOLERANCE_MM, PARTS, export_parts
from reflector_opt.cad.printability import (
    PrintabilityReport,
    check_printability,
    mesh_wall_thickness,
    shell_thickness_on_mesh,
)
from reflector_opt.cad.solids import Parts, build_parts, pose
from reflector_opt.cad.tessellation import circle_segments, sphere_segments, to_trimesh
from reflector_opt.cad.verification import RayCheck, verification_poses, verify_distances
from reflector_opt.design.layout import Layout, plan_layout
from reflector_opt.design.parts import CadParameters, load_cad_parameters

__all__ = [
    "DEFAULT_TOLERANCE_MM",
    "PARTS",
    "CadParameters",
    "CollisionReport",
    "Layout",
    "Parts",
    "PrintabilityReport",
    "RayCheck",
    "build_parts",
    "check_collisions",
    "check_printability",
    "circle_segments",
    "export_parts",
    "load_cad_parameters",
    "mesh_wall_thickness",
    "plan_layout",
    "pose",
    "shell_thickness_on_mesh",
    "sphere_segments",
    "to_trimesh",
    "verification_poses",
    "verify_distances",
]
