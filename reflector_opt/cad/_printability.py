"""Is a part printable?

Per part: manifold3d's status, a watertight and consistently wound trimesh of positive
volume, the bounding box inside the unit's envelope, and the thinnest wall against the
printable minimum (``mechanics.min_wall_mm``) — both as designed (closed-form values from the
layout) and as measured on the mesh. The clearance of the parts over the workspace is
proved apart, by :func:`reflector_opt.cad._clearance.check_collisions`.
"""

from dataclasses import dataclass, replace

import manifold3d as mf
import numpy as np
import trimesh

from reflector_opt.design._polar import relative_azimuth
from reflector_opt.util._display import Summarised, fmt, vector

#: A ray leaving a face inwards measures a wall only if the face it exits through faces
#: back within this angle (a slab); smaller exit angles are corners, not walls.
WALL_FACING_DEG = 60.0


def mesh_wall_thickness(solid, search_mm=3.0, facing_deg=WALL_FACING_DEG, facet_mm=0.0):
    """Thinnest wall of a solid, measured by casting a ray inward from every mesh face.

    From each face centre a ray runs along the inward normal to where it leaves the solid.
    That length is a wall thickness when the exit face's outward normal lies within
    ``facing_deg`` of the ray (two roughly opposite surfaces); a ray that leaves through a
    face meeting it at a glancing angle has crossed a corner, not a wall, and is not counted.
    Nor is a ray from a face narrower than ``facet_mm`` (its height across its longest edge):
    where two tessellated surfaces meet, one stands proud of the other by at most the chord
    tolerance, and the sliver of a step between them faces along the surface, so its ray runs
    along the part instead of through a wall (a 0.004 mm step measured 0.48 mm beside a sensor
    window, where the body is 4 mm wide).

    Parameters
    ----------
    solid : manifold3d.Manifold
        The part; its mesh (:meth:`~manifold3d.Manifold.to_mesh64`) is what is measured.
    search_mm : float
        Rays are cast this far; a part with no thinner wall reports ``inf``.
    facing_deg : float
        Largest angle between the ray and the exit face's normal for a wall, degrees.
    facet_mm : float
        Faces narrower than this cast no ray, mm (the chord tolerance: a tessellation's step).

    Returns
    -------
    (float, numpy.ndarray)
        The thinnest wall in mm and the face centre where it was measured (shape (3,)).
    """
    mesh = solid.to_mesh64()
    v = np.asarray(mesh.vert_properties, dtype=float)[:, :3]
    tri = v[np.asarray(mesh.tri_verts)]
    centres = tri.mean(axis=1)
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area2 = np.linalg.norm(normals, axis=1)
    longest = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2).max(axis=1)
    keep = (area2 > 1e-12) & (area2 >= facet_mm * longest)  # height = 2·area / longest edge
    centres, normals = centres[keep], normals[keep] / area2[keep, None]
    reach = float(search_mm)
    starts = centres - 1e-6 * normals
    ends = starts - reach * normals
    cos_facing = np.cos(np.deg2rad(facing_deg))
    thinnest, where = np.inf, np.full(3, np.nan)
    # manifold3d casts one ray segment per call (in C++, about 40 µs each).
    for k in range(len(starts)):
        hits = solid.ray_cast(tuple(starts[k]), tuple(ends[k]))
        if not hits:
            continue
        first = hits[0]
        if -np.dot(first.normal, normals[k]) >= cos_facing:
            length = first.distance * reach
            if length < thinnest:
                thinnest, where = length, centres[k]
    return float(thinnest), where


def shell_thickness_on_mesh(mesh, layout, tolerance_mm):
    """Thinnest reflecting shell of the reflector mesh, measured vertex to surface.

    Every mesh vertex on the inner sphere (within the chord tolerance of radius r_i) below
    the top of the band (within the tolerance: the vertices where a patch's edges meet the
    band's top lie on the faceted edge) is taken, and its distance to the nearest point of the
    triangles that lie on the reflecting sphere (corners within the tolerance of r_s about s0,
    normal along the sphere's, within a patch's azimuths) is measured exactly: the distance
    between the two surfaces, the layout's "reflecting shell"
    (:func:`reflector_opt.design._layout.plan_layout`).

    Parameters
    ----------
    mesh : trimesh.Trimesh
        The reflector part at zero pose.
    layout : reflector_opt.design._layout.Layout
    tolerance_mm : float
        Chord tolerance the mesh was built with, mm.

    Returns
    -------
    float
        Thinnest shell, mm (``inf`` if no shell was found).
    """
    v = mesh.vertices
    slack = tolerance_mm + 1e-6
    centre = np.asarray(layout.sphere_centre_mm)
    on_outer = np.abs(np.linalg.norm(v - centre, axis=1) - layout.sphere_radius_mm) <= slack
    radial = mesh.triangles_center - centre
    facing_out = np.einsum("ij,ij->i", mesh.face_normals, radial) >= 0.99 * np.linalg.norm(
        radial, axis=1
    )
    outer_faces = np.all(on_outer[mesh.faces], axis=1) & facing_out
    outer_faces &= _within_patches(mesh.triangles_center, layout.patches)
    radius = np.linalg.norm(v, axis=1)
    band_top_z = radius * np.sin(np.deg2rad(layout.band_top_deg))
    on_inner = (np.abs(radius - layout.inner_radius_mm) <= slack) & (v[:, 2] <= band_top_z + slack)
    if not np.any(outer_faces) or not np.any(on_inner):
        return float("inf")
    outer = trimesh.Trimesh(v, mesh.faces[outer_faces], process=False)
    _, distance, _ = trimesh.proximity.closest_point(outer, v[on_inner])
    return float(distance.min())


def _within_patches(points, patches):
    """True where points (shape (n, 3), mm) lie within some patch's azimuth range.

    Where the dome's outer surface happens to pass within the tolerance of the reflecting
    sphere (beside the patches, at the band's top), its faces would pass for the reflecting
    surface and the dome be measured as the shell.
    """
    azimuth = np.degrees(np.arctan2(points[:, 1], points[:, 0]))
    inside = np.zeros(len(points), dtype=bool)
    for patch in patches:
        lo, hi = patch.azimuth_deg
        inside |= np.abs(relative_azimuth(azimuth, 0.5 * (lo + hi))) <= 0.5 * (hi - lo) + 1e-6
    return inside


@dataclass(frozen=True, repr=False)
class PrintabilityReport(Summarised):
    """Printability of one part.

    Attributes
    ----------
    part : str
    manifold : bool
        manifold3d built the solid without error and it is not empty.
    watertight, winding_consistent : bool
        Every edge of the mesh joins exactly two faces; the faces are consistently oriented.
    volume_mm3 : float
        Enclosed volume (positive for an outward-oriented closed mesh), mm³.
    bounds_mm : list
        Axis-aligned bounding box [[x, y, z] min, [x, y, z] max], mm.
    inside_envelope : bool
        Within the unit's diameter and the part's height range.
    min_wall_required_mm : float
        Printable minimum (``mechanics.min_wall_mm``).
    thinnest_wall : str
        Name of the thinnest designed wall.
    thinnest_wall_mm : float
        Its thickness as designed (closed form), mm.
    mesh_wall_mm : float
        Thinnest wall measured on the mesh by inward rays, mm.
    shell_mesh_mm : float or None
        Reflecting shell measured on the mesh (reflector only), mm.
    problems : tuple of str
        One line for each failed check; empty when the part is printable.
    """

    part: str
    manifold: bool
    watertight: bool
    winding_consistent: bool
    volume_mm3: float
    bounds_mm: list
    inside_envelope: bool
    min_wall_required_mm: float
    thinnest_wall: str
    thinnest_wall_mm: float
    mesh_wall_mm: float
    shell_mesh_mm: float | None
    problems: tuple[str, ...]

    def _summary(self):
        """Title and (label, value) rows of :class:`PrintabilityReport`."""
        yes = {True: "yes", False: "no"}
        rows = [
            (
                "manifold / watertight / consistent winding",
                f"{yes[self.manifold]} / {yes[self.watertight]} / {yes[self.winding_consistent]}",
            ),
            ("volume", fmt(self.volume_mm3, unit="mm³")),
            ("bounds", f"{vector(self.bounds_mm[0], 2)} to {vector(self.bounds_mm[1], 2, 'mm')}"),
            ("inside the envelope", yes[self.inside_envelope]),
            (
                "thinnest wall",
                f"{self.thinnest_wall}: {fmt(self.thinnest_wall_mm, unit='mm')} "
                f"(required {fmt(self.min_wall_required_mm, unit='mm')})",
            ),
            ("thinnest wall on the mesh", fmt(self.mesh_wall_mm, unit="mm")),
            ("shell on the mesh", fmt(self.shell_mesh_mm, unit="mm")),
        ]
        rows += [("problem", line) for line in self.problems[:8]]
        state = "printable" if self.ok else f"{len(self.problems)} problems"
        return f"PrintabilityReport: {self.part}, {state}", rows

    @property
    def ok(self):
        """True when every check passed."""
        return not self.problems

    def to_dict(self):
        """JSON-ready dict (an unmeasured wall — none thinner than the search — is None)."""
        out = {k: getattr(self, k) for k in self.__dataclass_fields__}
        for key in ("mesh_wall_mm", "shell_mesh_mm"):
            if out[key] is not None and not np.isfinite(out[key]):
                out[key] = None
        out["problems"] = list(self.problems)
        out["ok"] = self.ok
        return out


def check_printability(part, solid, mesh, layout, tolerance_mm):
    """Run every printability check on one part.

    Parameters
    ----------
    part : {"reflector", "body"}
    solid : manifold3d.Manifold
        The part as built.
    mesh : trimesh.Trimesh
        The mesh that is written.
    layout : reflector_opt.design._layout.Layout
    tolerance_mm : float
        Chord tolerance, mm: the mesh may measure thinner than designed by up to twice this.

    Returns
    -------
    PrintabilityReport
    """
    required = layout.min_wall_mm
    walls = layout.reflector_walls_mm if part == "reflector" else layout.body_walls_mm
    thinnest = min(walls, key=walls.get)
    manifold = solid.status() == mf.Error.NoError and not solid.is_empty()
    outside = _envelope_problem(part, mesh, layout)
    mesh_wall, _ = mesh_wall_thickness(solid, facet_mm=tolerance_mm)
    shell = shell_thickness_on_mesh(mesh, layout, tolerance_mm) if part == "reflector" else None
    report = PrintabilityReport(
        part=part,
        manifold=bool(manifold),
        watertight=bool(mesh.is_watertight),
        winding_consistent=bool(mesh.is_winding_consistent),
        volume_mm3=float(mesh.volume),
        bounds_mm=mesh.bounds.tolist(),
        inside_envelope=outside is None,
        min_wall_required_mm=required,
        thinnest_wall=thinnest,
        thinnest_wall_mm=float(walls[thinnest]),
        mesh_wall_mm=float(mesh_wall),
        shell_mesh_mm=shell,
        problems=(),
    )
    problems = _problems(report, solid, outside, 2.0 * tolerance_mm)
    return replace(report, problems=tuple(problems))


def _envelope_problem(part, mesh, layout):
    """The line saying how a part's mesh leaves the envelope, or None if it stays inside."""
    bounds = mesh.bounds
    # the body within its own heights; the reflector part from the body's bottom (it hangs
    # into it) to the top of its flange
    z0 = layout.body_bottom_z_mm
    z1 = layout.flange_top_z_mm if part == "reflector" else layout.body_top_z_mm
    eps = 1e-6
    radial = float(np.hypot(mesh.vertices[:, 0], mesh.vertices[:, 1]).max())
    inside = (
        radial <= layout.envelope_radius_mm + eps
        and z0 - eps <= bounds[0, 2]
        and (bounds[1, 2] <= z1 + eps)
    )
    if inside:
        return None
    return (
        f"{part}: extends outside the envelope (radius {radial:.3f} mm of "
        f"{layout.envelope_radius_mm:g}, z {bounds[0, 2]:.2f}…{bounds[1, 2]:.2f} mm of "
        f"{z0:.2f}…{z1:.2f})"
    )


def _problems(report, solid, outside, slack):
    """One line for each check a part's report fails; ``outside`` is the envelope's line
    (or None) and ``slack`` how much thinner than designed the mesh may measure, mm."""
    part, required, volume = report.part, report.min_wall_required_mm, report.volume_mm3
    problems = []
    if not report.manifold:
        problems.append(f"{part}: manifold3d could not build a valid solid ({solid.status()})")
    if not report.watertight:
        problems.append(f"{part}: the mesh is not watertight")
    if not report.winding_consistent:
        problems.append(f"{part}: the mesh's faces are not consistently oriented")
    if not volume > 0.0:
        problems.append(f"{part}: the mesh encloses no positive volume ({volume:.4g} mm³)")
    if outside is not None:
        problems.append(outside)
    if report.thinnest_wall_mm < required:
        problems.append(
            f"{part}: the {report.thinnest_wall} is {report.thinnest_wall_mm:.3f} mm thick, "
            f"below the printable minimum {required:g} mm (mechanics.min_wall_mm)"
        )
    shell = report.shell_mesh_mm
    measured = min(report.mesh_wall_mm, np.inf if shell is None else shell)
    if measured < required - slack:
        problems.append(
            f"{part}: a wall measures {measured:.3f} mm on the mesh, below the printable "
            f"minimum {required:g} mm (mechanics.min_wall_mm)"
        )
    return problems
