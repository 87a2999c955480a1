"""Printable CAD of a design: the reflector part and the unit body as verified STL and 3MF.

Solids are described once by constructive solid geometry on exact primitives
(:mod:`reflector_opt.cad._shapes`), built with manifold3d, meshed to a chord tolerance,
checked for printability (closed, oriented, positive volume, inside the envelope, walls above
the printable minimum, no collision over the workspace) and verified against the model: rays
from the sensors hit the mesh at the Eq 3 distance.
With the optional build123d, the printed parts are also built from the same description as
exact solids, checked against the meshes and written as STEP files
(:mod:`reflector_opt.cad._step`). See docs/cad.md.
"""

import lazy_loader

#: The modules that define the public names, and the names each gives; a module is
#: imported the first time one of its names is used.
_MODULES = {
    "_export": ("DEFAULT_TOLERANCE_MM", "PARTS", "CheckedParts", "check_parts", "export_parts"),
    "_clearance": ("check_collisions", "prove_clearance"),
    "_solids": ("build_parts", "to_manifold"),
    "_printability": ("check_printability",),
    "_verification": ("verify_distances",),
    "_tessellation": ("circle_segments", "sphere_segments", "to_trimesh"),
}

# lazy_loader attaches a package's own modules: the names of design's parts and layout are
# given as they are.
from reflector_opt.design._layout import Layout, plan_layout  # noqa: E402
from reflector_opt.design._parts import CadParameters, load_cad_parameters  # noqa: E402

__getattr__, _, __all__ = lazy_loader.attach(__name__, submod_attrs=_MODULES)
__all__ += ["CadParameters", "Layout", "load_cad_parameters", "plan_layout"]


def __dir__():
    return list(__all__)
