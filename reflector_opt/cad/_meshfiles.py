"""Binary STL and 3MF files, written atomically (temporary file, then rename) and reproducibly.

STL carries one mesh (float32 coordinates, millimetres by convention), serialised by trimesh
(:mod:`trimesh.exchange.stl`): an 80-byte header of zeros, the triangle count and the
triangles, nothing else.

3MF (3D Manufacturing Format core specification) is a zip package holding an XML model with
its unit set to millimetre; it may hold several named objects (an assembly). It is written by
lib3mf, the 3MF Consortium's reference implementation, which also checks what it writes. The
production extension's ``p:UUID`` of the build, of each object and of each build item is
set to a version-5 UUID of the content it names (the object's name, vertices and triangles)
rather than lib3mf's random one, and lib3mf gives every entry of the package a fixed date, so
the same meshes give the same bytes. Coordinates are single precision (lib3mf's
``Position``), as in the STL: about 1e-6 of the part's size.
"""

import hashlib
import uuid

import lib3mf
import numpy as np
from trimesh.exchange.stl import export_stl

from reflector_opt.util._fileio import write_file

#: Namespace of the content-derived UUIDs (itself the version-5 UUID of a fixed URL).
_UUID_NAMESPACE = uuid.UUID("89cdbe09-d753-59d9-9a42-876b1ead338c")


def write_stl(path, mesh):
    """Write one mesh as a binary STL file, atomically.

    Parameters
    ----------
    path : str or pathlib.Path
    mesh : trimesh.Trimesh
        Coordinates in mm.
    """
    write_file(path, lambda tmp: tmp.write_bytes(export_stl(mesh)), ".stl")


def content_uuid(*parts):
    """The version-5 UUID of some content: the same content, the same UUID.

    Parameters
    ----------
    *parts : str or bytes
        What the UUID names, in order.

    Returns
    -------
    str
        The UUID in its hyphenated form.
    """
    digest = hashlib.sha256()
    for part in parts:
        data = part.encode() if isinstance(part, str) else part
        digest.update(len(data).to_bytes(8, "little") + data)
    return str(uuid.uuid5(_UUID_NAMESPACE, digest.hexdigest()))


def _geometry(mesh):
    """The mesh's vertices (float32, mm) and triangles as lib3mf's structure arrays."""
    vertices = np.ascontiguousarray(mesh.vertices, dtype=np.float32)
    faces = np.ascontiguousarray(mesh.faces, dtype=np.uint32)
    positions = (lib3mf.Position * len(vertices)).from_buffer_copy(vertices)
    triangles = (lib3mf.Triangle * len(faces)).from_buffer_copy(faces)
    return positions, triangles


def threemf_bytes(objects):
    """A 3MF package of named meshes, as bytes (the same meshes give the same bytes).

    Parameters
    ----------
    objects : dict of str to trimesh.Trimesh
        Object name → mesh (mm), in the order they are written; each becomes a named object
        and a build item (its ``partnumber`` is the name too), in place (identity transform).

    Returns
    -------
    bytes
    """
    wrapper = lib3mf.get_wrapper()
    model = wrapper.CreateModel()
    model.SetUnit(lib3mf.ModelUnit.MilliMeter)
    item_uuids = []
    for name, mesh in objects.items():
        positions, triangles = _geometry(mesh)
        part = model.AddMeshObject()
        part.SetName(name)
        part.SetGeometry(positions, triangles)
        object_uuid = content_uuid("object", name, bytes(positions), bytes(triangles))
        part.SetUUID(object_uuid)
        item = model.AddBuildItem(part, wrapper.GetIdentityTransform())
        item.SetPartNumber(name)
        item_uuids.append(content_uuid("item", object_uuid))
        item.SetUUID(item_uuids[-1])
    model.SetBuildUUID(content_uuid("build", *item_uuids))
    return bytes(model.QueryWriter("3mf").WriteToBuffer())


def write_3mf(path, objects):
    """Write named meshes as one 3MF package (unit: millimetre), atomically.

    Parameters
    ----------
    path : str or pathlib.Path
    objects : dict of str to trimesh.Trimesh
        Object name → mesh (mm); each becomes a named object and a build item (its
        ``partnumber`` is the name too), in place (identity transform).
    """
    write_file(path, lambda tmp: tmp.write_bytes(threemf_bytes(objects)), ".3mf")
