"""Does the printed part have the surface the optimiser modelled?

For poses over the workspace, a ray from each sensor position f towards the rotated sphere
centre s1 = Rx(roll)·Ry(pitch)·s0 is cast onto the reflector mesh posed at that pose; it must
hit at the distance the model predicts, d = ‖f − s1‖ − r_s (paper Eq 3), to within the chord
tolerance: the ray runs along the sphere's normal, and the inscribed mesh lies between the
sphere and a chord tolerance inside it.

Posing the mesh by R and casting the ray (f, s1 − f) is the same as casting the ray
(Rᵀf, s0 − Rᵀf) at the unposed mesh, which is what is done, so one ray accelerator serves
every pose. The rays are cast with trimesh, independently of manifold3d that built the part.
"""

from dataclasses import asdict, dataclass

import numpy as np
from trimesh.ray.ray_triangle import RayMeshIntersector

from reflector_opt.model._geometry import rotation_x, rotation_y, sensor_distance


@dataclass(frozen=True)
class RayCheck:
    """Result of :func:`verify_distances`.

    Attributes
    ----------
    rays : int
        Rays cast (poses × sensors).
    missed : int
        Rays that did not hit the mesh.
    max_error_mm : float
        Largest absolute difference of the mesh distance and the Eq 3 distance over the
        rays that hit, mm.
    mean_error_mm : float
        Mean of (mesh distance − Eq 3 distance), mm (positive: the mesh lies inside the
        sphere, as an inscribed mesh does).
    tolerance_mm : float
        The chord tolerance the errors are held to, mm.
    """

    rays: int
    missed: int
    max_error_mm: float
    mean_error_mm: float
    tolerance_mm: float

    @property
    def passed(self):
        """Every ray hit, within the tolerance."""
        return self.missed == 0 and self.max_error_mm <= self.tolerance_mm

    def to_dict(self):
        """JSON-ready dict."""
        return {**asdict(self), "passed": self.passed}


def verification_poses(design, n_per_axis=7):
    """A pitch × roll grid over the workspace, ends (corners) included.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Pitch and roll in degrees, both of shape (n_per_axis², ).
    """
    pitch = np.linspace(*design.workspace.pitch_deg, n_per_axis)
    roll = np.linspace(*design.workspace.roll_deg, n_per_axis)
    pitch, roll = np.meshgrid(pitch, roll, indexing="ij")
    return pitch.ravel(), roll.ravel()


def verify_distances(mesh, design, tolerance_mm, pitch_deg=None, roll_deg=None):
    """Cast Eq 3 rays onto the posed reflector mesh and compare the hit distances.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        The reflector part at zero pose, mm.
    design : reflector_opt.design._design.Design
    tolerance_mm : float
        Chord tolerance the mesh was built with, mm.
    pitch_deg, roll_deg : array_like, optional
        1-D poses, degrees; :func:`verification_poses` by default.

    Returns
    -------
    RayCheck
    """
    if pitch_deg is None:
        pitch_deg, roll_deg = verification_poses(design)
    pitch = np.atleast_1d(np.asarray(pitch_deg, dtype=float))
    roll = np.atleast_1d(np.asarray(roll_deg, dtype=float))
    refl = design.reflector
    s0 = np.asarray(refl.centre_mm, dtype=float)
    f = design.positions_mm
    expected = sensor_distance(f, s0, refl.radius_mm, pitch, roll)  # (P, S)
    rotations = rotation_x(roll) @ rotation_y(pitch)  # (P, 3, 3)
    origins = np.einsum("pji,sj->psi", rotations, f).reshape(-1, 3)  # Rᵀ f
    directions = s0 - origins
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    _, index_ray, hits = RayMeshIntersector(mesh).intersects_id(
        origins, directions, return_locations=True, multiple_hits=False
    )
    hits = np.reshape(hits, (-1, 3))  # no hit at all comes back as shape (0,)
    distance = np.einsum("ij,ij->i", hits - origins[index_ray], directions[index_ray])
    error = distance - expected.ravel()[index_ray]
    return RayCheck(
        rays=len(origins),
        missed=len(origins) - len(np.unique(index_ray)),
        max_error_mm=float(np.abs(error).max()) if len(error) else float("inf"),
        mean_error_mm=float(error.mean()) if len(error) else float("nan"),
        tolerance_mm=float(tolerance_mm),
    )
