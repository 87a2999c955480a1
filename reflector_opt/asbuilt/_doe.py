"""Bayesian D-optimal experiment design: the algebra of choosing poses, on plain matrices.

Each candidate pose i contributes an S × p block A_i (S sensors, p parameters, in prior-std
units; :class:`reflector_opt.asbuilt._poses.PoseInformation` computes them for one unit of a
design). A plan S has the Bayesian information matrix M(S) = I + Σ_{i∈S} A_iᵀA_i: the
posterior precision in prior-std units, whose inverse's diagonal is each parameter's
(posterior / prior) variance and whose log-determinant is the information the plan gains over
the prior, in nats (2 Σ log(prior/posterior std) along the principal axes).

* :func:`information_matrix` — M of a set of blocks;
* :func:`greedy_selection` — D-optimal forward selection over the candidates, each step the
  pose of largest det(I_S + A_i M⁻¹ A_iᵀ) (the matrix determinant lemma: a rank-S update),
  M⁻¹ kept by the Woodbury identity;
* :func:`exchange` — Fedorov's exchange (the modified form of Cook & Nachtsheim 1980: each
  plan pose in turn swapped for the candidate that raises det M most) until no swap helps;
* :func:`d_optimal` — the two in turn;
* :func:`poses_needed` — how many D-optimal poses bring every *determinable* parameter's
  posterior std below a target fraction of its prior std (determinable: it gets there with
  every candidate pose).

Nothing here knows of sensors or designs: the functions take the blocks as an array of shape
(N, S, p). A pose is used at most once. Reference: Atkinson, Donev & Tobias, *Optimum
Experimental Designs, with SAS* (2007), ch. 11–12 (D-optimality, exchange algorithms) and
ch. 18 (Bayesian designs).
"""

from dataclasses import dataclass

import numpy as np

from reflector_opt.util._errors import InputError

#: Largest number of exchange passes over the plan.
MAX_PASSES = 20

#: A swap is taken when it raises log det M by more than this (nats).
_SWAP_GAIN = 1e-9


def information_matrix(rows):
    """M = I + Σ A_iᵀA_i of the blocks ``rows`` (shape (n, S, p)): shape (p, p)."""
    flat = rows.reshape(-1, rows.shape[-1])
    return np.eye(rows.shape[-1]) + flat.T @ flat


def std_ratio(information):
    """Posterior over prior std of every parameter, sqrt(diag M⁻¹): shape (p,)."""
    return np.sqrt(np.diag(np.linalg.inv(information)))


def greedy_selection(rows, n_poses, stop_variance=None):
    """Bayesian D-optimal forward selection: each step the pose that raises det M most.

    With M⁻¹ known, adding pose i multiplies det M by det(I_S + A_i M⁻¹ A_iᵀ) (the matrix
    determinant lemma), evaluated for every candidate at once; M⁻¹ is then updated by the
    Woodbury identity, M⁻¹ − M⁻¹A_iᵀ (I_S + A_i M⁻¹ A_iᵀ)⁻¹ A_i M⁻¹. No pose is taken twice.

    Parameters
    ----------
    rows : numpy.ndarray
        Shape (N, S, p): the candidates' blocks
        (:attr:`reflector_opt.asbuilt._poses.PoseInformation.rows`).
    n_poses : int
        Poses to select, at most N.
    stop_variance : numpy.ndarray, optional
        Shape (p,): stop early once every diag M⁻¹ is at most this (``inf``: no limit).

    Returns
    -------
    order : numpy.ndarray
        Shape (n,): candidate indices in the order taken (n = n_poses unless stopped).
    gains : numpy.ndarray
        Shape (n,): log det M gained at each step, nats (their sum is log det M).
    variances : numpy.ndarray
        Shape (n, p): diag M⁻¹ after each step (posterior over prior variance).
    """
    n_candidates, n_sensors, p = rows.shape
    if not 1 <= n_poses <= n_candidates:
        raise InputError(f"plan size: expected 1 to {n_candidates} poses, got {n_poses}")
    inverse = np.eye(p)
    taken = np.zeros(n_candidates, dtype=bool)
    order, gains, variances = [], [], []
    transposed = rows.transpose(0, 2, 1)
    for _ in range(int(n_poses)):
        projected = rows @ inverse  # (N, S, p): A_i M⁻¹
        update = np.eye(n_sensors) + projected @ transposed
        gain = np.linalg.slogdet(update)[1]
        gain[taken] = -np.inf
        i = int(np.argmax(gain))
        inverse = inverse - projected[i].T @ np.linalg.solve(update[i], projected[i])
        inverse = 0.5 * (inverse + inverse.T)
        taken[i] = True
        order.append(i)
        gains.append(gain[i])
        variances.append(np.diag(inverse).copy())
        if stop_variance is not None and np.all(variances[-1] <= stop_variance):
            break
    return np.array(order), np.array(gains), np.array(variances)


def exchange(rows, chosen, max_passes=MAX_PASSES):
    """Fedorov exchange: swap plan poses for candidates while det M rises.

    Each pass visits every pose of the plan: with that pose removed (a rank-S downdate,
    det factor det(I_S − A_i M⁻¹ A_iᵀ)) the candidate that restores the most information is
    found as in :func:`greedy_selection`, and swapped in if it beats the pose it replaces.

    Parameters
    ----------
    rows : numpy.ndarray
        Shape (N, S, p): the candidates' blocks.
    chosen : array_like of int
        The starting plan (distinct candidate indices).
    max_passes : int
        Passes over the plan at most.

    Returns
    -------
    numpy.ndarray
        The improved plan's candidate indices (same size; log det M never lower).
    """
    chosen = np.array(chosen, dtype=int)
    identity = np.eye(rows.shape[1])
    transposed = rows.transpose(0, 2, 1)
    for _ in range(int(max_passes)):
        inverse = np.linalg.inv(information_matrix(rows[chosen]))  # afresh each pass: no drift
        swaps = 0
        for k in range(len(chosen)):
            a = rows[chosen[k]]
            down = identity - a @ inverse @ a.T
            loss = np.linalg.slogdet(down)[1]
            without = inverse + (a @ inverse).T @ np.linalg.solve(down, a @ inverse)
            projected = rows @ without
            update = identity + projected @ transposed
            gain = np.linalg.slogdet(update)[1]
            gain[chosen] = -np.inf
            j = int(np.argmax(gain))
            if gain[j] + loss > _SWAP_GAIN:
                chosen[k] = j
                inverse = without - projected[j].T @ np.linalg.solve(update[j], projected[j])
                swaps += 1
        if swaps == 0:
            break
    return chosen


def d_optimal(rows, n_poses):
    """A D-optimal plan of ``n_poses`` candidates: greedy selection, then exchange.

    Parameters
    ----------
    rows : numpy.ndarray
        Shape (N, S, p): the candidates' blocks.
    n_poses : int

    Returns
    -------
    numpy.ndarray
        Candidate indices of the plan.
    """
    order, _, _ = greedy_selection(rows, n_poses)
    return exchange(rows, order)


def minimum_poses(rows):
    """The fewest poses an identification accepts: one voltage per parameter, rounded up.

    ``rows`` has shape (N, S, p): ceil(p / S).
    """
    n_sensors, p = rows.shape[1:]
    return -(-p // n_sensors)


@dataclass(frozen=True)
class PoseCount:
    """Poses a D-optimal plan needs to bring each determinable parameter to the target.

    Attributes
    ----------
    target : float
        Posterior over prior std to reach (0.5: halve the prior's).
    n_poses : int
        The plan size that brings every determinable parameter there (0 if none is).
    needed : dict of str to int or None
        Per parameter, the poses of the D-optimal sequence after which it first meets the
        target; None for a parameter that does not even with every candidate.
    ratio_all : numpy.ndarray
        Posterior over prior std with every candidate pose, shape (p,).
    indices : numpy.ndarray
        Candidate indices of the chosen plan (greedy, then exchange if that keeps the
        target).
    """

    target: float
    n_poses: int
    needed: dict
    ratio_all: np.ndarray
    indices: np.ndarray

    @property
    def determinable(self):
        """Names of the parameters that reach the target."""
        return tuple(name for name, n in self.needed.items() if n is not None)


def poses_needed(rows, names, target):
    """The D-optimal plan size that brings every determinable parameter below the target.

    The greedy sequence is nested, so each parameter's posterior variance falls along it;
    the count is the step at which the last determinable parameter meets the target, and at
    least :func:`minimum_poses` (the identification refuses fewer voltages than
    parameters). The sequence stops there. The plan of that size is then improved by
    :func:`exchange`; if the exchange (which raises det M, not each marginal) loses a
    parameter's target, the greedy plan is kept.

    Parameters
    ----------
    rows : numpy.ndarray
        Shape (N, S, p): the candidates' blocks.
    names : sequence of str
        The p parameters' names.
    target : float
        Posterior over prior std to reach, in (0, 1).

    Returns
    -------
    PoseCount
    """
    if not 0.0 < target < 1.0:
        raise InputError(
            f"target std: expected a fraction of the prior std in (0, 1), got {target}"
        )
    ratio_all = std_ratio(information_matrix(rows))
    determinable = ratio_all <= target
    needed = dict.fromkeys(names)
    if not determinable.any():
        return PoseCount(float(target), 0, needed, ratio_all, np.zeros(0, dtype=int))
    stop = np.where(determinable, target**2, np.inf)
    order, _, variances = greedy_selection(rows, len(rows), stop)
    met = variances <= target**2
    for j in np.flatnonzero(determinable):  # at most every candidate (rounding)
        needed[names[j]] = int(np.argmax(met[:, j])) + 1 if met[:, j].any() else len(order)
    # the identification needs a voltage per parameter at least
    n_poses = max(max(n for n in needed.values() if n is not None), minimum_poses(rows))
    if n_poses > len(order):
        order, _, _ = greedy_selection(rows, n_poses)
    indices = exchange(rows, order[:n_poses])
    if np.any(std_ratio(information_matrix(rows[indices]))[determinable] > target):
        indices = order[:n_poses]
    return PoseCount(float(target), n_poses, needed, ratio_all, np.asarray(indices))
