"""Binary STL and 3MF files, written atomically (temporary file, then rename).

STL carries one mesh (float32 coordinates, millimetres by convention). 3MF (3D Manufacturing
Format core specification, 2015/02) is a zip package holding an XML model with its unit set
to millimetre; it may hold several named objects (an assembly).
"""

from __future__ import annotations

import io
import zipfile

import numpy as np
from trimesh.exchange.stl import export_stl

from reflector_opt.util.errors import InputError
from reflector_opt.util.fileio import atomic_path

__all__ = ["write_3mf", "write_stl"]

_CONTENT_TYPES = """<?xml version="1.0" encoding="UTF-8"?>
<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">
 <Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>
 <Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>
</Types>
"""

_RELS = """<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">
 <Relationship Target="/3D/3dmodel.model" Id="rel0"
  Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>
</Relationships>
"""

_CORE = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"


def _lines(fmt, rows):
    buffer = io.StringIO()
    np.savetxt(buffer, rows, fmt=fmt)
    return buffer.getvalue()


def _model_xml(objects, title):
    parts = [
        '<?xml version="1.0" encoding="UTF-8"?>\n',
        f'<model unit="millimeter" xml:lang="en-US" xmlns="{_CORE}">\n',
        f' <metadata name="Title">{title}</metadata>\n',
        " <resources>\n",
    ]
    for i, (name, mesh) in enumerate(objects.items(), start=1):
        parts.append(f'  <object id="{i}" type="model" name="{name}">\n   <mesh>\n    <vertices>\n')
        parts.append(_lines('     <vertex x="%.6f" y="%.6f" z="%.6f"/>', mesh.vertices))
        parts.append("    </vertices>\n    <triangles>\n")
        parts.append(_lines('     <triangle v1="%d" v2="%d" v3="%d"/>', mesh.faces))
        parts.append("    </triangles>\n   </mesh>\n  </object>\n")
    parts.append(" </resources>\n <build>\n")
    parts.extend(f'  <item objectid="{i}"/>\n' for i in range(1, len(objects) + 1))
    parts.append(" </build>\n</model>\n")
    return "".join(parts)


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


def write_3mf(path, objects, title="reflector-opt"):
    """Write named meshes as one 3MF package (unit: millimetre), atomically.

    Parameters
    ----------
    path : str or pathlib.Path
    objects : dict of str to trimesh.Trimesh
        Object name → mesh (mm); each becomes an object and a build item.
    title : str
        Model title metadata.
    """

    def write(tmp):
        with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as z:
            z.writestr("[Content_Types].xml", _CONTENT_TYPES)
            z.writestr("_rels/.rels", _RELS)
            z.writestr("3D/3dmodel.model", _model_xml(objects, title))

    _write(path, ".3mf", write)
