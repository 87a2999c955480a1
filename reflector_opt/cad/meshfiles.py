"""Binary STL and 3MF files, written atomically (temporary file, then rename).

STL carries one mesh (float32 coordinates, millimetres by convention). 3MF (3D Manufacturing
Format core specification, 2015/02) is a zip package holding an XML model with its unit set
to millimetre; it may hold several named objects (an assembly). Both are serialised by
trimesh (:mod:`trimesh.exchange.stl`; :mod:`trimesh.exchange.threemf`, which writes the XML
with lxml, so object names are escaped).
"""

from __future__ import annotations

import trimesh
from trimesh.exchange.stl import export_stl

from reflector_opt.util.errors import InputError
from reflector_opt.util.fileio import atomic_path

__all__ = ["write_3mf", "write_stl"]


def _write(path, suffix, write):
    try:
        with atomic_path(path, suffix=suffix) as tmp:
            write(tmp)
    except OSError as exc:
        raise InputError(f"cannot write {path}: {exc.strerror or exc}") from None


def write_stl(path, mesh):
    """Write one mesh as a binary STL file, atomically.

    Parameters
    ----------
    path : str or pathlib.Path
    mesh : trimesh.Trimesh
        Coordinates in mm.
    """
    _write(path, ".stl", lambda tmp: tmp.write_bytes(export_stl(mesh)))


def write_3mf(path, objects):
    """Write named meshes as one 3MF package (unit: millimetre), atomically.

    Parameters
    ----------
    path : str or pathlib.Path
    objects : dict of str to trimesh.Trimesh
        Object name → mesh (mm); each becomes a named object and a build item (its
        ``partnumber`` is the name too), in place (identity transform). trimesh's writer
        declares the model's unit as millimetre.
    """
    scene = trimesh.Scene()
    for name, mesh in objects.items():
        scene.add_geometry(mesh, node_name=name, geom_name=name)
    _write(path, ".3mf", lambda tmp: tmp.write_bytes(scene.export(file_type="3mf")))
