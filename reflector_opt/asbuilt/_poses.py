"""Candidate poses and what each says about one unit's as-built parameters.

For one unit of a design, the p parameters of
:class:`~reflector_opt.asbuilt._parameters.ParameterLayout` (the shared surface ρ, f and the unit's
own block) each have a prior std σ_p (the tolerance model's), and each pose i gives the S × p
sensitivity block (S sensors)

    A_i = diag(1/σ_eff) · ∂V(pose_i)/∂x · diag(σ_p),

the Jacobian of the weighted voltage residuals of
:class:`~reflector_opt.asbuilt._problem.IdentificationProblem` at the nominal design (the same
residuals, weights σ_eff and central differences the identification uses), in prior-std
units: the blocks :mod:`reflector_opt.asbuilt._doe` chooses plans from.

* :func:`candidate_poses` — the candidate grid over the workspace
  (:data:`CANDIDATE_STEP_DEG`);
* :func:`pose_information` — the blocks A_i of a set of poses, a :class:`PoseInformation`;
* :func:`visiting_order` — the order a rig visits a plan in.
"""

from dataclasses import dataclass, field

import numpy as np

from reflector_opt.asbuilt._doe import information_matrix, std_ratio
from reflector_opt.asbuilt._parameters import ParameterLayout
from reflector_opt.asbuilt._problem import IdentificationProblem, UnitData
from reflector_opt.model._forward import voltages
from reflector_opt.tolerance._builtunit import REFERENCE_SIGMA_DEG
from reflector_opt.util._errors import InputError

#: Step of the candidate grid over the workspace, degrees (±15° gives 31 × 31 = 961 poses).
CANDIDATE_STEP_DEG = 1.0

#: Most candidate poses (the greedy path over all of them costs N² S p² operations).
MAX_CANDIDATES = 4000


@dataclass(frozen=True)
class PoseInformation:
    """Each pose's sensitivity block for one unit's as-built parameters, in prior-std units.

    Attributes
    ----------
    poses_deg : numpy.ndarray
        Shape (n, 2): pitch, roll, degrees.
    rows : numpy.ndarray
        Shape (n, S, p): A_i = ∂(V/σ_eff)/∂(x/σ_p) at each pose, dimensionless.
    names : tuple of str
        The p free parameters (shared surface first, then the unit's block).
    prior_std : numpy.ndarray
        Shape (p,): prior std of each, in its own unit (mm, degrees, V, fraction).
    settings : dict
        The keyword arguments of :func:`pose_information` it was computed with (design,
        prior, reference noise), so that :meth:`at` computes other poses alike.
    """

    poses_deg: np.ndarray
    rows: np.ndarray
    names: tuple
    prior_std: np.ndarray
    settings: dict = field(default_factory=dict, repr=False, compare=False)

    def __len__(self):
        return len(self.poses_deg)

    def information(self, indices=None):
        """M = I + Σ A_iᵀA_i over ``indices`` (default every pose), shape (p, p)."""
        rows = self.rows if indices is None else self.rows[np.asarray(indices, dtype=int)]
        return information_matrix(rows)

    def log_det(self, indices=None):
        """log det M: the information gained over the prior, nats."""
        return float(np.linalg.slogdet(self.information(indices))[1])

    def ratio(self, indices=None):
        """Posterior over prior std of every parameter, shape (p,)."""
        return std_ratio(self.information(indices))

    def at(self, poses_deg):
        """The same information at other poses (same design, prior and noise)."""
        return pose_information(poses_deg=poses_deg, **self.settings)


def pose_information(
    design,
    poses_deg,
    *,
    tolerances=None,
    surface_std=None,
    reference_sigma_deg=REFERENCE_SIGMA_DEG,
):
    """The sensitivity blocks of one unit's as-built parameters at the given poses.

    The Jacobian is
    :meth:`reflector_opt.asbuilt._problem.IdentificationProblem.data_jacobian` at the
    nominal design (the design's own voltages as the data), so the weights σ_eff (voltage
    noise with quantisation and the angle reference's noise through the slope) are the
    identification's.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    poses_deg : array_like
        Shape (n, 2): pitch, roll within the workspace, degrees.
    tolerances : reflector_opt.tolerance._tolerances.Tolerances, optional
        The prior (default: the tolerance model's defaults).
    surface_std : dict, optional
        Prior std of ``reflectance`` and ``specular_fraction`` (absolute).
    reference_sigma_deg : float
        RMS noise of the angle reference at each pose, degrees.

    Returns
    -------
    PoseInformation
    """
    poses = np.asarray(poses_deg, dtype=float)
    if poses.ndim != 2 or poses.shape[1] != 2 or len(poses) == 0 or not np.isfinite(poses).all():
        raise InputError(f"poses: expected finite (n, 2) angles, got shape {poses.shape}")
    layout = ParameterLayout(design, 1, tolerances, surface_std)
    nominal = voltages(design, poses[:, 0], poses[:, 1])
    problem = IdentificationProblem(
        layout, [UnitData("design", nominal, poses)], reference_sigma_deg
    )
    jacobian = problem.data_jacobian(np.zeros(layout.size))
    free = problem.free
    names = tuple(
        name.split(": ")[-1] for name, keep in zip(layout.names(), free, strict=True) if keep
    )
    settings = {
        "design": design,
        "tolerances": tolerances,
        "surface_std": surface_std,
        "reference_sigma_deg": reference_sigma_deg,
    }
    rows = (jacobian[:, free] * problem.prior_std[free]).reshape(len(poses), layout.n_sensors, -1)
    return PoseInformation(poses, rows, names, problem.prior_std[free], settings)


def candidate_poses(workspace, step_deg=CANDIDATE_STEP_DEG):
    """The candidate grid over the workspace, both ends included: shape (n, 2), degrees.

    Parameters
    ----------
    workspace : reflector_opt.design._components.Workspace
    step_deg : float
        Grid step, degrees.

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    InputError
        More than :data:`MAX_CANDIDATES` poses.
    """
    pitch, roll = workspace.axes(step_deg)
    if len(pitch) * len(roll) > MAX_CANDIDATES:
        raise InputError(
            f"candidate step {step_deg:g}°: {len(pitch) * len(roll):,} candidate poses, more "
            f"than {MAX_CANDIDATES:,}; give a coarser step"
        )
    return workspace.poses(step_deg)


def visiting_order(poses_deg):
    """The order a rig visits a plan in: row by row of pitch, every other row reversed.

    Parameters
    ----------
    poses_deg : array_like
        Shape (n, 2): pitch, roll, degrees.

    Returns
    -------
    numpy.ndarray
        Shape (n,): indices into ``poses_deg`` in visiting order.
    """
    poses = np.asarray(poses_deg, dtype=float)
    order = []
    for k, pitch in enumerate(np.unique(poses[:, 0])):
        row = np.flatnonzero(poses[:, 0] == pitch)
        row = row[np.argsort(poses[row, 1], kind="stable")]
        order.extend(row[::-1] if k % 2 else row)
    return np.array(order, dtype=int)
