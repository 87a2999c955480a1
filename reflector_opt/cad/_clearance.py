"""Clearance between the turning and the fixed solids, proved over the whole workspace.

The reflector part and the bearing's inner ring turn about O by R = Rx(roll)·Ry(pitch). For a
point p and two poses whose pitches differ by Δg and rolls by Δa,

    ‖Rx(a)Ry(g)p − Rx(a′)Ry(g′)p‖ ≤ ‖p‖ (|Δg| + |Δa|)          (angles in radians),

since each factor turns p about one axis through O by at most its angle and a chord is
shorter than its arc. So over a cell of poses [g ± h_g] × [a ± h_a] no point of a turning
solid whose points lie within r_max of O moves farther than r_max (h_g + h_a) from where it
is at the cell's centre, and a gap larger than that at the centre proves clearance over the
whole cell. A cell that is not proved is split into four until it is, a contact is found, or
the cell is smaller than :data:`SMALLEST_CELL_DEG` (then it is reported as not proved).

A rotation about O keeps every point at its distance from O, so two faces whose distances
from O never come closer than the gap stay apart at every pose; the fixed faces are grouped
by distance from O, and each group is measured only against the turning faces that come
within :data:`RADIAL_MARGIN_MM` of it — which is what lets concentric surfaces (the dome in
the body's cavity, the inner ring in its pocket) be proved over large cells. Gaps are
measured between the triangle meshes with coal's bounding-volume hierarchies (the maintained
successor of FCL); where a gap is zero the overlap volume is measured with manifold3d.
Clearance of the surfaces everywhere proves the solids apart only if they are apart at one
pose, so the overlap volume is measured once at the centre of the workspace too.
"""

import math
from dataclasses import asdict, dataclass

import coal
import numpy as np
import trimesh

from reflector_opt.cad._background import BackgroundCall
from reflector_opt.cad._solids import pose_matrix
from reflector_opt.util._display import Summarised, fmt

#: Fixed faces farther than this from every turning face in distance from O are not measured
#: at each pose (their radial gap bounds the gap at every pose), mm.
RADIAL_MARGIN_MM = 0.1
#: Width in distance from O of a group of fixed faces, mm.
GROUP_WIDTH_MM = 0.05
#: Turning faces wider than this in distance from O are split to edges this long, mm.
PIECE_MM = 3.0
#: Fixed groups are joined when that adds at most this share of the turning faces to measure
#: against either.
MERGE_SLACK = 0.02
#: Cells narrower than this (pitch or roll) are not split further, degrees.
SMALLEST_CELL_DEG = 0.05
#: Intersection volume below which two solids count as touching at most, mm³.
CONTACT_VOLUME_MM3 = 1e-9


@dataclass(frozen=True)
class CollisionReport:
    """Clearance between the turning and the fixed solids over the workspace.

    Attributes
    ----------
    cells : int
        Cells of poses proved clear (pitch × roll rectangles covering the workspace).
    unproved_cells : int
        Cells neither proved clear nor found in contact, down to the smallest cell.
    poses : int
        Poses at which gaps were measured (cell centres).
    contact_pose_deg : (float, float) or None
        Pitch and roll of the first pose found with a zero gap, degrees.
    max_intersection_mm3 : float
        Largest boolean intersection volume found (at the contact pose and at the centre
        of the workspace), mm³.
    min_clearance_mm : float
        Smallest gap measured between faces within reach of each other, mm.
    worst_pose_deg : (float, float)
        Pitch and roll where that gap was measured, degrees.
    proved_clearance_mm : float
        Lower bound of the gap over every proved cell, mm (≤ ``min_clearance_mm``).
    radial_clearance_mm : float
        Smallest gap in distance from O between faces not measured pose by pose, mm.
    """

    cells: int
    unproved_cells: int
    poses: int
    contact_pose_deg: tuple[float, float] | None
    max_intersection_mm3: float
    min_clearance_mm: float
    worst_pose_deg: tuple[float, float]
    proved_clearance_mm: float
    radial_clearance_mm: float

    @property
    def collided(self):
        """True when a pose with zero gap or an overlap of the solids was found."""
        return self.contact_pose_deg is not None or self.max_intersection_mm3 > CONTACT_VOLUME_MM3

    @property
    def collision_free(self):
        """True when every cell of the workspace is proved clear."""
        return not self.collided and self.unproved_cells == 0

    @property
    def problem(self):
        """One line if the turning and the fixed solids meet somewhere, else None."""
        if not self.collided:
            return None
        g, a = self.contact_pose_deg or self.worst_pose_deg
        return (
            f"the reflector part and the body collide at pitch {g:g}°, roll {a:g}° "
            f"(overlap {self.max_intersection_mm3:.3g} mm³)"
        )

    def to_dict(self):
        """JSON-ready dict."""
        return {**asdict(self), "collision_free": self.collision_free}


def radial_extent(mesh):
    """Smallest and largest distance from O of each face of a mesh, exactly, mm.

    Parameters
    ----------
    mesh : trimesh.Trimesh

    Returns
    -------
    numpy.ndarray
        Shape (n_faces, 2).
    """
    triangles = mesh.triangles
    nearest = trimesh.triangles.closest_point(triangles, np.zeros((len(triangles), 3)))
    return np.column_stack(
        [np.linalg.norm(nearest, axis=1), np.linalg.norm(triangles, axis=2).max(axis=1)]
    )


def _bvh(vertices, faces):
    model = coal.BVHModelOBBRSS()
    model.beginModel(len(faces), len(vertices))
    model.addVertices(np.ascontiguousarray(vertices, dtype=np.float64))
    model.addTriangles(np.ascontiguousarray(faces, dtype=np.int64))
    model.endModel()
    return model


def _submesh(mesh, keep):
    faces = mesh.faces[keep]
    used, inverse = np.unique(faces, return_inverse=True)
    return mesh.vertices[used], inverse.reshape(faces.shape)


def _groups(extent):
    """Fixed faces grouped by distance from O: face indices and the group's extent.

    Faces whose nearest and farthest distances from O fall in the same bins of
    :data:`GROUP_WIDTH_MM` form a group, so a group's extent is within a bin of each face's.
    """
    bins = np.floor(extent / GROUP_WIDTH_MM).astype(np.int64)
    _, label = np.unique(bins, axis=0, return_inverse=True)
    order = np.argsort(label.ravel(), kind="stable")
    starts = np.flatnonzero(np.diff(label.ravel()[order])) + 1
    return [(g, (extent[g, 0].min(), extent[g, 1].max())) for g in np.split(order, starts)]


class _Group:
    """Fixed faces of one radial group, and the turning faces within the margin of them.

    The gap is measured first against the whole turning mesh (a lower bound of the gap to
    the faces near in distance from O); only when that does not prove a cell is a hierarchy
    of the near faces alone built (once) and measured.
    """

    def __init__(self, whole, pieces, near, fixed_bvh, fixed_reach_mm, near_cache):
        self.whole, self.pieces, self.near, self.fixed = whole, pieces, near, fixed_bvh
        # A turning point farther from O than every fixed face of the group cannot meet one
        # at any pose, so only points up to the group's reach need the travel bound.
        reach = float(np.linalg.norm(pieces.triangles[near], axis=2).max())
        self.reach_mm = min(reach, fixed_reach_mm)
        self._cache, self._key = near_cache, np.packbits(near).tobytes()

    def gap(self, rotation, travel):
        """The gap at a pose, and the gap to the near faces if it is needed to prove a cell
        of that angular travel (radians; else the gap again), mm."""
        gap, nearest = _gap(self.whole, self.fixed, rotation)
        # Measuring the near faces alone helps only if the nearest face is not one of them.
        if gap <= 0.0 or gap > self.reach_mm * travel or self.near[nearest]:
            return gap, gap
        if self._key not in self._cache:
            self._cache[self._key] = _bvh(*_submesh(self.pieces, self.near))
        return gap, _gap(self._cache[self._key], self.fixed, rotation)[0]


def _groups_to_measure(moving, fixed):
    """The radial groups to measure pose by pose, and the radial gap of all other faces.

    Turning faces spanning more than :data:`PIECE_MM` in distance from O are split into
    triangles no longer than that (the same surface), so that a long face — a shaft's side
    from end to end — does not stand close in distance from O to everything it passes.
    """
    extent = radial_extent(moving)
    long = extent[:, 1] - extent[:, 0] > PIECE_MM
    if long.any():  # nothing to subdivide otherwise
        vertices, faces = trimesh.remesh.subdivide_to_size(
            moving.vertices, moving.faces[long], max_edge=PIECE_MM
        )
        faces = np.concatenate([moving.faces[~long], faces])
        moving = trimesh.Trimesh(vertices, faces, process=False)
    whole = _bvh(moving.vertices, moving.faces)
    moving_extent, fixed_extent = radial_extent(moving), radial_extent(fixed)
    lo_sorted, hi_sorted = np.sort(moving_extent[:, 0]), np.sort(moving_extent[:, 1])

    def near_count(lo, hi):
        """Turning faces within the radial margin of [lo, hi]."""
        below = np.searchsorted(hi_sorted, lo - RADIAL_MARGIN_MM)
        above = len(lo_sorted) - np.searchsorted(lo_sorted, hi + RADIAL_MARGIN_MM, side="right")
        return len(lo_sorted) - below - above

    # Groups are joined while that adds few turning faces to measure against either.
    merged = []
    for group, (lo, hi) in sorted(_groups(fixed_extent), key=lambda g: g[1]):
        if merged:
            last, (last_lo, last_hi) = merged[-1]
            joined = (min(lo, last_lo), max(hi, last_hi))
            grows = near_count(*joined) - min(near_count(lo, hi), near_count(last_lo, last_hi))
            if grows <= MERGE_SLACK * len(lo_sorted):
                merged[-1] = (np.concatenate([last, group]), joined)
                continue
        merged.append((group, (lo, hi)))
    groups, radial, cache = [], np.inf, {}
    for group, (lo, hi) in merged:
        gap = np.maximum(lo - moving_extent[:, 1], moving_extent[:, 0] - hi)
        near = gap < RADIAL_MARGIN_MM
        if (~near).any():
            radial = min(radial, float(gap[~near].min()))
        if near.any():
            groups.append(_Group(whole, moving, near, _bvh(*_submesh(fixed, group)), hi, cache))
    return groups, radial


def _gap(moving, fixed, rotation):
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    placed = coal.Transform3s(rotation, np.zeros(3))
    gap = coal.distance(moving, placed, fixed, coal.Transform3s(), request, result)
    return max(gap, 0.0), result.b1


@dataclass(repr=False)
class ClearanceProof(Summarised):
    """What the proof over cells of the workspace found, before any overlap volume.

    Attributes are those of :class:`CollisionReport` (``contact``, ``min_gap``,
    ``worst_pose``, ``proved_gap`` and ``radial_gap`` are its ``contact_pose_deg``,
    ``min_clearance_mm``, ``worst_pose_deg``, ``proved_clearance_mm`` before the radial gap,
    and ``radial_clearance_mm``). Plain numbers only, so that it passes between processes.
    """

    proved_cells: int = 0
    unproved_cells: int = 0
    poses: int = 0
    contact: tuple | None = None
    min_gap: float = np.inf
    worst_pose: tuple = (0.0, 0.0)
    proved_gap: float = np.inf
    radial_gap: float = np.inf

    def _summary(self):
        """Title and (label, value) rows of :class:`ClearanceProof`."""
        pose = (
            "none"
            if self.contact is None
            else f"pitch {self.contact[0]:g}°, roll {self.contact[1]:g}°"
        )
        rows = [
            ("cells proved / unproved", f"{self.proved_cells} / {self.unproved_cells}"),
            ("poses checked", str(self.poses)),
            ("contact", pose),
            (
                "least gap",
                f"{fmt(self.min_gap, unit='mm')} at pitch {self.worst_pose[0]:g}°, "
                f"roll {self.worst_pose[1]:g}°",
            ),
            ("proved gap", fmt(self.proved_gap, unit="mm")),
            ("radial gap", fmt(self.radial_gap, unit="mm")),
        ]
        return "ClearanceProof", rows

    def merged(self, other):
        """Both tallies as one; this one's contact first."""
        worst = self if self.min_gap <= other.min_gap else other
        return ClearanceProof(
            proved_cells=self.proved_cells + other.proved_cells,
            unproved_cells=self.unproved_cells + other.unproved_cells,
            poses=self.poses + other.poses,
            contact=self.contact or other.contact,
            min_gap=worst.min_gap,
            worst_pose=worst.worst_pose,
            proved_gap=min(self.proved_gap, other.proved_gap),
            radial_gap=min(self.radial_gap, other.radial_gap),
        )


class _Search:
    """Proof of cells of poses against the radial groups, splitting cells until proved."""

    def __init__(self, groups):
        self.groups = groups

    def cell(self, centre, half, open_groups, tally):
        """Prove a cell (centre and half-widths in degrees); return the groups still open."""
        rotation = pose_matrix(*centre)[:, :3]
        travel = math.radians(half[0] + half[1])
        tally.poses += 1
        still = []
        for k in open_groups:
            group = self.groups[k]
            gap, near_gap = group.gap(rotation, travel)
            if gap < tally.min_gap:
                tally.min_gap, tally.worst_pose = gap, (float(centre[0]), float(centre[1]))
            if gap <= 0.0:
                tally.contact = (float(centre[0]), float(centre[1]))
                return [k]
            # Point by point the gap over the cell is at least max(‖p‖ − reach,
            # gap − ‖p‖·travel), which is smallest where the two meet.
            bound = (near_gap - group.reach_mm * travel) / (1.0 + travel)
            if bound > 0.0:
                tally.proved_gap = min(tally.proved_gap, bound)
            else:
                still.append(k)
        return still

    def run(self, cells, tally=None):
        """Prove cells ``(centre, half, open groups)``, splitting each into four until it
        is proved, a contact is found or it is smaller than :data:`SMALLEST_CELL_DEG`."""
        tally = tally or ClearanceProof()
        stack = list(cells)
        while stack and tally.contact is None:
            centre, half, open_groups = stack.pop()
            still = self.cell(centre, half, open_groups, tally)
            if tally.contact is not None:
                break
            if not still:
                tally.proved_cells += 1
            elif 2.0 * max(half) < SMALLEST_CELL_DEG:
                tally.unproved_cells += 1
            else:
                stack.extend(_quarters(centre, half, still))
        return tally

    def prove(self, pitch_range, roll_range):
        """Prove the workspace, starting from it as one cell; its quarters, if it is not
        proved at once, are shared between this process and a forked one."""
        (g0, g1), (a0, a1) = pitch_range, roll_range
        centre, half = ((g0 + g1) / 2.0, (a0 + a1) / 2.0), ((g1 - g0) / 2.0, (a1 - a0) / 2.0)
        tally = ClearanceProof()
        still = self.cell(centre, half, range(len(self.groups)), tally)
        if tally.contact is not None:
            return tally
        if not still:
            tally.proved_cells += 1
            return tally
        quarters = list(_quarters(centre, half, still))
        with BackgroundCall(lambda: self.run(quarters[:2])) as other:
            mine = self.run(quarters[2:], tally)
            return other.result().merged(mine)


def _quarters(centre, half, open_groups):
    h = (half[0] / 2.0, half[1] / 2.0)
    return (
        ((centre[0] + sg * h[0], centre[1] + sa * h[1]), h, open_groups)
        for sg in (-1, 1)
        for sa in (-1, 1)
    )


def _fixed_mesh(meshes):
    """The fixed solids the reflector part may meet (body, outer ring, sensors), one mesh."""
    return trimesh.util.concatenate([meshes["body"], meshes["outer_ring"], meshes["sensors"]])


def overlap_mm3(solids, pose_deg, turning=("reflector", "inner_ring")):
    """Largest boolean intersection volume of the turning solids with the fixed ones at a pose.

    The reflector part against the body, the bearing's outer ring and the sensors; the inner
    ring against the body only (the bearing's two rings are one bought part).

    Parameters
    ----------
    solids : reflector_opt.cad._solids.Parts
    pose_deg : (float, float)
        Pitch and roll, degrees.
    turning : sequence of {"reflector", "inner_ring"}
        The turning solids to measure.

    Returns
    -------
    float
        mm³.
    """
    posed = solids.posed(*pose_deg)
    against = {
        "reflector": solids.body + solids.outer_ring + solids.sensors,
        "inner_ring": solids.body,
    }
    return max((posed[name] ^ against[name]).volume() for name in turning)


def prove_clearance(meshes, workspace):
    """Prove the turning meshes clear of the fixed ones over the workspace (gaps only).

    Turning: the reflector part and the bearing's inner ring. Fixed: the body, the bearing's
    outer ring and the sensor packages; the inner ring is checked against the body only (the
    two bearing rings are one bought part). Works on the meshes with numpy and coal alone
    (no manifold3d, whose thread pool does not survive a fork), so it may run in a forked
    process; :func:`collision_report` adds the overlap volumes.

    Parameters
    ----------
    meshes : dict of str to trimesh.Trimesh
        Zero-pose meshes of ``reflector``, ``inner_ring``, ``body``, ``outer_ring`` and
        ``sensors``.
    workspace : reflector_opt.design._components.Workspace

    Returns
    -------
    ClearanceProof
    """
    groups, radial = _groups_to_measure(meshes["reflector"], _fixed_mesh(meshes))
    ring_groups, ring_radial = _groups_to_measure(meshes["inner_ring"], meshes["body"])
    proof = _Search(groups + ring_groups).prove(workspace.pitch_deg, workspace.roll_deg)
    proof.radial_gap = min(radial, ring_radial)
    return proof


def collision_report(parts, workspace, proof):
    """The proof with the overlap volumes of the solids, as a :class:`CollisionReport`.

    Surfaces apart at every pose prove the solids apart only if they are apart at one pose,
    so the boolean intersection volume is measured at the centre of the workspace, and at
    the contact if the proof found one.

    Parameters
    ----------
    parts : reflector_opt.cad._solids.Parts
    workspace : reflector_opt.design._components.Workspace
    proof : ClearanceProof
        From :func:`prove_clearance` on the meshes of ``parts``.

    Returns
    -------
    CollisionReport
    """
    centre = (0.5 * sum(workspace.pitch_deg), 0.5 * sum(workspace.roll_deg))
    overlap = overlap_mm3(parts, centre)
    if proof.contact is not None:
        overlap = max(overlap, overlap_mm3(parts, proof.contact))
    return CollisionReport(
        cells=proof.proved_cells,
        unproved_cells=proof.unproved_cells,
        poses=proof.poses,
        contact_pose_deg=proof.contact,
        max_intersection_mm3=float(overlap),
        min_clearance_mm=float(proof.min_gap),
        worst_pose_deg=proof.worst_pose,
        proved_clearance_mm=float(min(proof.proved_gap, proof.radial_gap)),
        radial_clearance_mm=float(proof.radial_gap),
    )


def check_collisions(parts, design, meshes=None):
    """Prove the turning solids clear of the fixed ones over the whole workspace.

    :func:`prove_clearance` on the meshes, then :func:`collision_report`.

    Parameters
    ----------
    parts : reflector_opt.cad._solids.Parts
    design : reflector_opt.design._design.Design
    meshes : dict of str to trimesh.Trimesh, optional
        Meshes of the solids already made (keys as :meth:`Parts.posed`); the others are made.

    Returns
    -------
    CollisionReport
    """
    from reflector_opt.cad._tessellation import to_trimesh

    meshes = dict(meshes or {})
    for name in ("reflector", "inner_ring", "body", "outer_ring", "sensors"):
        if name not in meshes:
            meshes[name] = to_trimesh(getattr(parts, name))
    proof = prove_clearance(meshes, design.workspace)
    return collision_report(parts, design.workspace, proof)


def gap_at_pose(meshes, pose_deg):
    """Gap between the reflector part and the fixed solids at one pose, mm (0 if they meet).

    Parameters
    ----------
    meshes : dict of str to trimesh.Trimesh
        Zero-pose meshes of ``reflector``, ``body``, ``outer_ring`` and ``sensors``.
    pose_deg : (float, float)
        Pitch and roll, degrees.

    Returns
    -------
    float
    """
    fixed = _fixed_mesh(meshes)
    moving = _bvh(meshes["reflector"].vertices, meshes["reflector"].faces)
    return float(_gap(moving, _bvh(fixed.vertices, fixed.faces), pose_matrix(*pose_deg)[:, :3])[0])
