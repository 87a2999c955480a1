"""Binary STL and 3MF files, written atomically (temporary file, then rename) and reproducibly.

STL carries one mesh (float32 coordinates, millimetres by convention), serialised by trimesh
(:mod:`trimesh.exchange.stl`): an 80-byte header of zeros, the triangle count and the
triangles, nothing else.

3MF (3D Manufacturing Format core specification 1.3, namespace ``…/core/2015/02``) is a zip
package holding an XML model with its unit set to millimetre; it may hold several named
objects (an assembly). The model declares the core namespace as the default and the
production extension's (``p``, ``…/production/2015/06``) once, on the ``model`` element, and
gives the build, each object and each build item its ``p:UUID``, as that extension asks of
a model that uses it; it is not listed as required, so a consumer without the extension
reads the core model. Each UUID is a version-5 UUID of the content it names (the object's
name, vertices and triangles), and the package's entries carry a fixed date, so the same
meshes give the same bytes.
"""

from __future__ import annotations

import hashlib
import io
import uuid
import zipfile
from xml.sax.saxutils import escape

import numpy as np
from trimesh.exchange.stl import export_stl

from reflector_opt.util.errors import InputError
from reflector_opt.util.fileio import atomic_path

__all__ = ["CORE_NAMESPACE", "PRODUCTION_NAMESPACE", "threemf_bytes", "write_3mf", "write_stl"]

#: XML namespace of the 3MF core specification.
CORE_NAMESPACE = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"
#: XML namespace of the 3MF production extension (its ``UUID`` attributes).
PRODUCTION_NAMESPACE = "http://schemas.microsoft.com/3dmanufacturing/production/2015/06"
#: Namespace of the content-derived UUIDs (itself the version-5 UUID of a fixed URL).
_UUID_NAMESPACE = uuid.UUID("89cdbe09-d753-59d9-9a42-876b1ead338c")
#: Date of every entry of a 3MF package (the earliest a zip file can hold).
_ZIP_DATE = (1980, 1, 1, 0, 0, 0)
_MODEL_PATH = "3D/3dmodel.model"
_RELATIONSHIPS = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
    f'<Relationship Target="/{_MODEL_PATH}" Id="rel0" '
    'Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>'
    "</Relationships>"
)
_CONTENT_TYPES = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">'
    '<Default Extension="rels" '
    'ContentType="application/vnd.openxmlformats-package.relationships+xml"/>'
    '<Default Extension="model" '
    'ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>'
    "</Types>"
)


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


def _attribute(text):
    """``text`` escaped for a double-quoted XML attribute."""
    return escape(text, {'"': "&quot;"})


def _object_xml(object_id, name, mesh, object_uuid):
    """One ``object`` element: the mesh's vertices (mm) and triangles."""
    vertices = np.asarray(mesh.vertices, dtype=float)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    vertex = '<vertex x="{}" y="{}" z="{}"/>' * len(vertices)
    triangle = '<triangle v1="{}" v2="{}" v3="{}"/>' * len(faces)
    return (
        f'<object id="{object_id}" name="{_attribute(name)}" type="model" p:UUID="{object_uuid}">'
        f"<mesh><vertices>{vertex.format(*vertices.ravel().tolist())}</vertices>"
        f"<triangles>{triangle.format(*faces.ravel().tolist())}</triangles></mesh></object>"
    )


def _model_xml(objects):
    """The 3MF model of named meshes: one object and one build item each, in place."""
    resources, items, item_uuids = [], [], []
    for object_id, (name, mesh) in enumerate(objects.items(), start=1):
        vertices = np.ascontiguousarray(mesh.vertices, dtype="<f8").tobytes()
        faces = np.ascontiguousarray(mesh.faces, dtype="<i8").tobytes()
        object_uuid = content_uuid("object", name, vertices, faces)
        item_uuid = content_uuid("item", object_uuid)
        resources.append(_object_xml(object_id, name, mesh, object_uuid))
        items.append(
            f'<item objectid="{object_id}" partnumber="{_attribute(name)}" p:UUID="{item_uuid}"/>'
        )
        item_uuids.append(item_uuid)
    build_uuid = content_uuid("build", *item_uuids)
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<model xmlns="{CORE_NAMESPACE}" xmlns:p="{PRODUCTION_NAMESPACE}" unit="millimeter">'
        f"<resources>{''.join(resources)}</resources>"
        f'<build p:UUID="{build_uuid}">{"".join(items)}</build>'
        "</model>"
    )


def threemf_bytes(objects):
    """A 3MF package of named meshes, as bytes (the same meshes give the same bytes).

    Parameters
    ----------
    objects : dict of str to trimesh.Trimesh
        Object name → mesh (mm), in the order they are written.

    Returns
    -------
    bytes
    """
    entries = {
        "[Content_Types].xml": _CONTENT_TYPES,
        "_rels/.rels": _RELATIONSHIPS,
        _MODEL_PATH: _model_xml(objects),
    }
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as package:
        for name, text in entries.items():
            info = zipfile.ZipInfo(name, date_time=_ZIP_DATE)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.create_system = 0  # no Unix permission bits: the same on every system
            package.writestr(info, text.encode(), compresslevel=6)
    return buffer.getvalue()


def write_3mf(path, objects):
    """Write named meshes as one 3MF package (unit: millimetre), atomically.

    Parameters
    ----------
    path : str or pathlib.Path
    objects : dict of str to trimesh.Trimesh
        Object name → mesh (mm); each becomes a named object and a build item (its
        ``partnumber`` is the name too), in place (identity transform).
    """
    _write(path, ".3mf", lambda tmp: tmp.write_bytes(threemf_bytes(objects)))
