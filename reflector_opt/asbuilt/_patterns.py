"""Plan patterns compared for identification: what the Fisher information predicts of each.

The D-optimal plan (:func:`reflector_opt.asbuilt._doe.d_optimal` over the candidates of a
:class:`~reflector_opt.asbuilt._poses.PoseInformation`) against the Sobol, grid and spiral
patterns of :mod:`reflector_opt.calibration._plans` of the same sizes: each plan's log det M
and each parameter's posterior over prior std (:class:`PatternRow`).
"""

from dataclasses import dataclass, field

import numpy as np

from reflector_opt.asbuilt._doe import d_optimal, information_matrix, std_ratio
from reflector_opt.asbuilt._poses import visiting_order
from reflector_opt.calibration._plans import make_plan, path_length_deg

#: Plan patterns compared for identification, in report order.
PATTERNS = ("d-optimal", "sobol", "grid")

#: Plan sizes compared (poses).
SIZES = (25, 50, 100, 200)


@dataclass(frozen=True)
class PatternRow:
    """What the Fisher information predicts for one plan.

    Attributes
    ----------
    pattern : str
    n_poses : int
    log_det : float
        log det M, nats.
    ratio : numpy.ndarray
        Shape (p,): posterior over prior std of each parameter.
    poses_deg : numpy.ndarray
        Shape (n, 2): the plan in visiting order, degrees.
    """

    pattern: str
    n_poses: int
    log_det: float
    ratio: np.ndarray
    poses_deg: np.ndarray = field(repr=False)

    def to_dict(self, names, target):
        """JSON-ready, with the parameters whose ratio is at most ``target``."""
        return {
            "pattern": self.pattern,
            "n_poses": self.n_poses,
            "log_det": self.log_det,
            "path_deg": path_length_deg(self.poses_deg),
            "posterior_prior_ratio": dict(zip(names, self.ratio.tolist(), strict=True)),
            "determined": [n for n, r in zip(names, self.ratio, strict=True) if r <= target],
        }


def pattern_row(pattern, poses, rows):
    """The :class:`PatternRow` of a plan from its poses (n, 2, degrees) and their blocks.

    A ``d-optimal`` plan is put in :func:`~reflector_opt.asbuilt._poses.visiting_order`; other
    patterns keep their own order.
    """
    information = information_matrix(rows)
    ordered = poses[visiting_order(poses)] if pattern == "d-optimal" else poses
    return PatternRow(
        pattern,
        len(poses),
        float(np.linalg.slogdet(information)[1]),
        std_ratio(information),
        ordered,
    )


def compare_patterns(info, sizes=SIZES, patterns=PATTERNS, seed=0):
    """The Fisher prediction of every pattern and size: log det M and each parameter's ratio.

    Parameters
    ----------
    info : reflector_opt.asbuilt._poses.PoseInformation
        The candidates (their settings give the design and prior of the other patterns).
    sizes : sequence of int
        Plan sizes (``grid`` takes the nearest square).
    patterns : sequence of str
        Among :data:`PATTERNS`, and ``spiral`` and ``raster``
        (:data:`reflector_opt.calibration._plans.PATTERNS`; the raster ignores the size).
    seed : int
        Scrambling seed of the Sobol points.

    Returns
    -------
    list of PatternRow
        Pattern by pattern, sizes in the order given.
    """
    workspace = info.settings["design"].workspace
    out = []
    for pattern in patterns:
        for n in sizes if pattern != "raster" else (None,):
            if pattern == "d-optimal":
                indices = d_optimal(info.rows, n)
                out.append(pattern_row(pattern, info.poses_deg[indices], info.rows[indices]))
            else:
                poses = make_plan(workspace, pattern, n, seed=seed)
                out.append(pattern_row(pattern, poses, info.at(poses).rows))
    return out
