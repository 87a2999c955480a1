"""What a Jacobian says about resolution: conditioning, the Cramér–Rao bound, folds, uniqueness.

* conditioning: the condition number of J = ∂(V1, V2)/∂(γ, α) and the sign of det J (a sign
  change is a fold: two poses near it give the same pair of voltages);
* resolution: the Cramér–Rao bound on the 1σ pitch and roll error, the square roots of the
  diagonal of σ_V² (JᵀJ)⁻¹, in degrees (σ_V the RMS of noise and ADC quantisation), at each
  pose (:func:`crlb_deg`) and over a set of poses, its worst case and RMS per angle
  (:func:`resolution_over_poses`);
* global uniqueness: the smallest voltage separation, in units of σ_V, of two poses at least
  1° apart, exactly on a grid (a compiled sweep over the poses sorted by one voltage) or to
  first order from J.

Pure functions of J (from :mod:`reflector_opt.analysis._jacobian`) or of the voltages over a
pose grid. No sensitivity (J singular somewhere) gives an infinite resolution and condition
number, never an error or a warning.
"""

import math
from dataclasses import dataclass

import numba
import numpy as np

from reflector_opt.model import _kernel as kernel

#: Pose separation of the global uniqueness check, degrees.
UNIQUENESS_POSE_SEPARATION_DEG = 1.0


# --- conditioning and resolution --------------------------------------------------------------


def _normal_matrix(jacobian):
    """Entries a, b, c of JᵀJ = [[a, b], [b, c]] and its eigenvalues (largest, smallest)."""
    j = np.asarray(jacobian, dtype=float)
    a = np.einsum("...i,...i->...", j[..., 0], j[..., 0])
    b = np.einsum("...i,...i->...", j[..., 0], j[..., 1])
    c = np.einsum("...i,...i->...", j[..., 1], j[..., 1])
    half_trace = 0.5 * (a + c)
    lam_max = half_trace + np.hypot(0.5 * (a - c), b)
    det = a * c - b * b
    # λ_min = det/λ_max is exact and avoids the cancellation of half_trace − hypot(...).
    lam_min = np.divide(det, lam_max, out=np.zeros_like(det), where=lam_max > 0.0)
    return a, b, c, det, lam_max, lam_min


def condition_number(jacobian):
    """2-norm condition number of J, σ_max/σ_min (its singular values).

    Parameters
    ----------
    jacobian : array_like, shape P + (n, 2)
        n ≥ 2 outputs against pitch and roll.

    Returns
    -------
    numpy.ndarray
        Shape P; ``inf`` where J is singular (no sensitivity in some direction).
    """
    *_, lam_max, lam_min = _normal_matrix(jacobian)
    with np.errstate(over="ignore"):  # a nearly singular J overflows to inf, as it should
        ratio = np.divide(lam_max, lam_min, out=np.full_like(lam_max, np.inf), where=lam_min > 0)
    return np.sqrt(ratio)


def crlb_deg(jacobian, sigma_v):
    """Cramér–Rao 1σ pitch and roll resolution, degrees.

    With independent Gaussian noise of RMS σ_V on every output, the Fisher information of
    (γ, α) is JᵀJ/σ_V², so any unbiased estimator has covariance at least σ_V² (JᵀJ)⁻¹.
    With JᵀJ = [[a, b], [b, c]]: ``σ_γ = σ_V·sqrt(c/(ac − b²))``, ``σ_α = σ_V·sqrt(a/(ac − b²))``.

    Parameters
    ----------
    jacobian : array_like, shape P + (n, 2)
        ∂V/∂(γ, α), V/deg.
    sigma_v : float
        RMS voltage noise per output (including quantisation), V.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        σ_γ and σ_α, shape P, degrees; ``inf`` where J is singular.

    References
    ----------
    S. M. Kay, *Fundamentals of Statistical Signal Processing: Estimation Theory* (1993),
    ch. 3 (the Cramér–Rao bound for a vector parameter in Gaussian noise).
    """
    a, _, c, det, _, lam_min = _normal_matrix(jacobian)
    ok = lam_min > 0.0
    with np.errstate(over="ignore"):  # a nearly singular J overflows to inf, as it should
        var_pitch = np.divide(c, det, out=np.full_like(det, np.inf), where=ok)
        var_roll = np.divide(a, det, out=np.full_like(det, np.inf), where=ok)
    return sigma_v * np.sqrt(var_pitch), sigma_v * np.sqrt(var_roll)


@dataclass(frozen=True)
class PoseResolution:
    """The Cramér–Rao 1σ resolution over a set of poses, per angle (pitch, roll).

    Attributes
    ----------
    worst_deg : numpy.ndarray
        Shape (2,): the largest σ_γ and σ_α over the poses, degrees.
    rms_deg : numpy.ndarray
        Shape (2,): ``sqrt(mean σ²)`` of each over the poses, degrees (the RMS error an
        efficient estimator reaches on poses drawn from the set).
    """

    worst_deg: np.ndarray
    rms_deg: np.ndarray

    @property
    def worst(self):
        """The larger worst case of pitch and roll, degrees."""
        return float(np.max(self.worst_deg))


def resolution_over_poses(jacobian, sigma_v):
    """Cramér–Rao 1σ resolution over poses: its worst case and RMS per angle, degrees.

    At each pose σ_γ, σ_α = σ_V·sqrt(diag((JᵀJ)⁻¹)) (:func:`crlb_deg`); over the poses the
    largest of each and ``sqrt(mean σ²)``. The one summary of the bound over a workspace grid
    or a set of validation poses (a unit's floor, the as-built report, the print loop).

    Parameters
    ----------
    jacobian : array_like, shape P + (n, 2)
        ∂V/∂(γ, α) at every pose, V/deg (the unit's own, its read-out gain included).
    sigma_v : float
        RMS voltage noise per output (including quantisation), V.

    Returns
    -------
    PoseResolution
        ``inf`` where J is singular at some pose.
    """
    sigma = crlb_deg(jacobian, sigma_v)
    return PoseResolution(
        worst_deg=np.array([np.max(s) for s in sigma]),
        rms_deg=np.sqrt([np.mean(s**2) for s in sigma]),
    )


def jacobian_determinant(jacobian):
    """det J of a two-output Jacobian, (V/deg)².

    Parameters
    ----------
    jacobian : array_like, shape P + (2, 2)

    Returns
    -------
    numpy.ndarray
        Shape P. Its sign must not change over the workspace (no fold).
    """
    j = np.asarray(jacobian, dtype=float)
    if j.shape[-2:] != (2, 2):
        raise ValueError(f"det J needs exactly two outputs, got shape {j.shape}")
    return j[..., 0, 0] * j[..., 1, 1] - j[..., 0, 1] * j[..., 1, 0]


def fold_fraction(determinant):
    """Fraction of poses where det J is zero or has the minority sign.

    Parameters
    ----------
    determinant : array_like
        det J at every pose.

    Returns
    -------
    (int, float)
        The prevailing sign (+1, −1, or 0 when det J is zero everywhere) and the fraction of
        poses that do not share it. 0.0 means no fold on the grid.
    """
    s = np.sign(np.asarray(determinant, dtype=float)).ravel()
    n_pos, n_neg = int(np.count_nonzero(s > 0)), int(np.count_nonzero(s < 0))
    if n_pos == n_neg == 0:
        return 0, 1.0
    sign = 1 if n_pos >= n_neg else -1
    return sign, 1.0 - max(n_pos, n_neg) / s.size


# --- global uniqueness ------------------------------------------------------------------------


def min_separation_sigma(
    volts, pitch_deg, roll_deg, sigma_v, min_pose_separation_deg=UNIQUENESS_POSE_SEPARATION_DEG
):
    """Smallest voltage distance, in σ_V, between two poses at least a given angle apart.

    Exact, without comparing all pairs: the poses are sorted by the output voltage of widest
    spread, and each is compared with the poses after it only while that voltage alone
    differs by less than the smallest distance found so far (no pair further along can be
    closer), skipping pairs closer in pose than the separation (:func:`_closest_apart`).

    Parameters
    ----------
    volts : array_like, shape P + (n,)
        Output voltages at every pose, V.
    pitch_deg, roll_deg : array_like
        The poses, degrees, broadcast to shape P.
    sigma_v : float
        RMS voltage noise per output, V (> 0).
    min_pose_separation_deg : float, optional
        Poses closer than this (Euclidean in (γ, α), degrees) are not compared.

    Returns
    -------
    float
        min ‖V(p) − V(q)‖/σ_V over pose pairs with ‖p − q‖ ≥ the separation; ``inf`` if no two
        poses are that far apart. A fold or a non-injective map gives a value near 0.
    """
    v = np.asarray(volts, dtype=float)
    pitch, roll = np.broadcast_arrays(
        np.asarray(pitch_deg, dtype=float), np.asarray(roll_deg, dtype=float)
    )
    poses = np.stack([pitch.ravel(), roll.ravel()], axis=-1)
    scaled = v.reshape(poses.shape[0], -1) / float(sigma_v)
    if poses.shape[0] < 2:
        return math.inf
    key = int(np.argmax(np.ptp(scaled, axis=0)))
    order = np.argsort(scaled[:, key], kind="stable")
    # Tolerate rounding in grid coordinates: poses exactly s apart count as s apart.
    s = float(min_pose_separation_deg) * (1.0 - 1e-9)
    return _closest_apart(
        np.ascontiguousarray(scaled[order]), np.ascontiguousarray(poses[order]), key, s * s
    )


@numba.njit(**kernel._OPTIONS)
def _closest_apart(values, poses, key, apart_sq):
    """Smallest Euclidean distance of two rows of ``values`` whose ``poses`` are apart.

    ``values`` (N, n) sorted by column ``key``; a pair counts when its poses (N, 2) differ by
    at least ``sqrt(apart_sq)``. A pair (i, j > i) is at least ``values[j, key] −
    values[i, key]`` apart, so the scan from i stops once that exceeds the best distance so
    far: the result is the exact minimum over all pairs (inf if no pair is apart).
    """
    n, outputs = values.shape
    best_sq = np.inf
    for i in range(n):
        for j in range(i + 1, n):
            dk = values[j, key] - values[i, key]
            if dk * dk >= best_sq:
                break
            dp, dr = poses[i, 0] - poses[j, 0], poses[i, 1] - poses[j, 1]
            if dp * dp + dr * dr < apart_sq:
                continue
            dist = 0.0
            for k in range(outputs):
                dv = values[i, k] - values[j, k]
                dist += dv * dv
            best_sq = min(best_sq, dist)
    return math.sqrt(best_sq)


def local_separation_sigma(
    jacobian, sigma_v, min_pose_separation_deg=UNIQUENESS_POSE_SEPARATION_DEG
):
    """First-order voltage separation of poses a given angle apart, in σ_V, worst over poses.

    Near a pose, poses s apart in the least sensitive direction differ in voltage by about
    ``s·sqrt(λ_min(JᵀJ))``. A grid coarser than s has no such pairs, so this stands in for
    them when the uniqueness check runs on a coarse grid (the search).

    Parameters
    ----------
    jacobian : array_like, shape P + (n, 2)
        ∂V/∂(γ, α), V/deg.
    sigma_v : float
        RMS voltage noise per output, V.
    min_pose_separation_deg : float, optional
        The separation s, degrees.

    Returns
    -------
    float
        ``min over poses of s·sqrt(λ_min)/σ_V``.
    """
    *_, lam_min = _normal_matrix(jacobian)
    return float(min_pose_separation_deg * np.sqrt(max(float(np.min(lam_min)), 0.0)) / sigma_v)
