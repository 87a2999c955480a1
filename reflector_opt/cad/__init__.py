"""Printable CAD of a design: the reflector part and the unit body as verified STL and 3MF.

Solids are described once by constructive solid geometry on exact primitives
(:mod:`reflector_opt.cad.shapes`), built with manifold3d, meshed to a chord tolerance,
checked for printability (closed, oriented, positive volume, inside the envelope, walls above
the printable minimum, no collision over the workspace) and verified against the model: rays
from the sensors hit the mesh at the Eq 3 distance.
With the optional build123d, the printed parts are also built from the same description as
exact solids, checked against the meshes and written as STEP files
(:mod:`reflector_opt.cad.step`). See docs/cad.md.
"""

from reflector_opt.util.lazy import lazy_exports

#: Each public name and the module that defines it, imported on first use.
_SOURCES = {
    "DEFAULT_TOLERANCE_MM": "reflector_opt.cad.export",
    "PARTS": "reflector_opt.cad.export",
    "CadParameters": "reflector_opt.design.parts",
    "ClearanceProof": "reflector_opt.cad.clearance",
    "CollisionReport": "reflector_opt.cad.clearance",
    "Layout": "reflector_opt.design.layout",
    "Parts": "reflector_opt.cad.solids",
    "PrintabilityReport": "reflector_opt.cad.printability",
    "RayCheck": "reflector_opt.cad.verification",
    "STEP_PARTS": "reflector_opt.cad.step",
    "build_parts": "reflector_opt.cad.solids",
    "build_step_parts": "reflector_opt.cad.step",
    "check_collisions": "reflector_opt.cad.clearance",
    "check_printability": "reflector_opt.cad.printability",
    "circle_segments": "reflector_opt.cad.tessellation",
    "collision_report": "reflector_opt.cad.clearance",
    "export_parts": "reflector_opt.cad.export",
    "load_cad_parameters": "reflector_opt.design.parts",
    "mesh_disagreement": "reflector_opt.cad.step",
    "mesh_wall_thickness": "reflector_opt.cad.printability",
    "plan_layout": "reflector_opt.design.layout",
    "pose": "reflector_opt.cad.solids",
    "prove_clearance": "reflector_opt.cad.clearance",
    "shell_thickness_on_mesh": "reflector_opt.cad.printability",
    "sphere_segments": "reflector_opt.cad.tessellation",
    "step_available": "reflector_opt.cad.step",
    "to_manifold": "reflector_opt.cad.solids",
    "to_solid": "reflector_opt.cad.step",
    "to_trimesh": "reflector_opt.cad.tessellation",
    "verification_poses": "reflector_opt.cad.verification",
    "verify_distances": "reflector_opt.cad.verification",
    "write_step": "reflector_opt.cad.step",
}

__all__ = list(_SOURCES)
__getattr__, __dir__ = lazy_exports(__name__, _SOURCES)
