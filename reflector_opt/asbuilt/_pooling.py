"""Systematic against random: the batch mean of the printed geometry and the unit scatter.

:func:`pool` separates, in the identified units of one print batch
(:class:`~reflector_opt.asbuilt._batch.Batch`), the deviation that repeats from print to print
— the batch mean μ, with its uncertainty — from the unit-to-unit scatter.

**Model** (random effects, in the prior-whitened geometry space z = x/σ_prior, σ_prior the
tolerance model's spread): each unit's deviation is θ_u = μ + η_u with η_u ~ N(0, τ²·I) — the
scatter has the tolerance model's shape and an estimated size τ (1: the tolerance model's
own) — and its identification is a measurement of θ_u whose information matrix and vector
follow from the unit's posterior N(z_u, C_u) under the prior N(0, I):
``H_u = C_u⁻¹ − I`` and ``h_u = C_u⁻¹ z_u`` (exact for a linear-Gaussian identification; it
undoes the prior's pull of the estimate towards the design).

* **What the batch's data determine**: the eigen-directions of the units' pooled information
  ``Σ_u H_u`` whose posterior/prior std ratio 1/√(1 + κ) is at most
  :data:`~reflector_opt.asbuilt._uncertainty.DETERMINED_RATIO` (κ ≥ 3) span the determined
  subspace D; the others are named and left alone. The scatter is left out of this test on
  purpose: it limits how well a few units pin the mean down, which the mean's uncertainty
  (below) states and the correction's significance test weighs; it does not make a
  combination the calibration sees undeterminable. (With the scatter in, ``W = Σ_u H_u
  (I + τ² H_u)⁻¹`` ≤ n/τ², and no direction could ever be determined by fewer than four
  units scattering as much as the tolerance model says.)
* **Scatter** (hierarchical, with a prior on τ): in the subspace E (dimension k) that each
  unit's own data determine (κ ≥ 3 of the units' mean information Σ_u H_u / n), each unit's
  data-only estimate m_u and covariance S_u (its posterior marginal on E with the prior
  divided out) follow m_u ~ N(μ, S_u + τ²I). With μ integrated out under a flat prior, the
  restricted (REML) likelihood of τ² is
  ``log L(τ²) = −½ [Σ_u log|V_u| + log|Σ_u V_u⁻¹| + Q(τ²)]``, ``V_u = S_u + τ²I``,
  ``Q(τ²) = Σ_u (m_u − μ̂)ᵀ V_u⁻¹ (m_u − μ̂)``, μ̂ the generalised-least-squares mean. The
  prior is a scaled-inverse-χ² on τ², ``τ² ~ Scale-Inv-χ²(ν₀, s₀²)`` with
  ν₀ = :data:`SCATTER_PRIOR_DOF` and s₀ = ``scatter_prior`` (1: centred on the tolerance
  model's scatter). τ² is its posterior mean, integrated on a grid of log τ². Where the units
  are measured exactly (S_u = 0) this is the conjugate result
  ``E[τ²] = (ν₀ s₀² + Q) / (ν₀ + (n − 1)k − 2)`` with Q the units' sum of squares about
  their mean. (The method of moments, Paule & Mandel 1982, used before, gave τ = 0.38 from 3
  units against 0.79 from 5 of the same batch in the benchmark: a 3-unit correction was
  overconfident.)
* **Batch mean**: μ̂ in D (m_u and S_u on D), with covariance ``(Σ_u (S_u + τ²I)⁻¹)⁻¹`` —
  each unit's posterior uncertainty and the scatter's, combined — given along its own
  independent directions, each with an estimate, a standard uncertainty and
  t = estimate/std (:class:`Direction`).

**Model form.** A bias of the identification (physics its model lacks) is the same in every
unit and does not average out: its covariance — the one the identification files record
(``covariance.model_form``, taken from posterior means to data-only estimates as the units'
are), or one simulated (:mod:`reflector_opt.asbuilt._model_form_bias`) — is added once to the batch
mean's.

**The angle reference.** When the identifications fitted their reference's zero offsets and
twist, part of each unit's uncertainty is the reference's (a sphere rotated about the joint
is a sphere moved: a pitch zero offset and a centre shift give the same voltages). The
reference may be wrong the same way for every unit (one instrument, one fixture), so that
part must not average out: the batch mean is the GLS mean of the units with their reference
known (``S_u|r``, from the covariance less :attr:`~reflector_opt.asbuilt._batch.Batch.reference`),
and the reference's part of the data-only covariance, ``S_u − S_u|r`` averaged over the
units, is added once, as the model form's is. A reference error therefore never looks like
a systematic print deviation resolved by many units.

With fewer than :data:`MIN_UNITS` units the systematic part cannot be told from the scatter:
τ is then not estimated but assumed — 0 with ``assume_systematic`` (the user's statement that
the deviation repeats: the uncertainty is the identification's alone), else 1 (the tolerance
model's scatter).
"""

from dataclasses import dataclass

import numpy as np

from reflector_opt.asbuilt._uncertainty import DETERMINED_RATIO, direction_name
from reflector_opt.util._display import Summarised, fmt
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import json_number

#: Units needed to tell the systematic part of a deviation from the unit-to-unit scatter.
MIN_UNITS = 3

#: Degrees of freedom ν₀ of the scaled-inverse-χ² prior on the scatter τ²: the tolerance
#: model's scatter counts as much as ν₀ squared residuals of the units (three units with
#: five determined combinations give (n − 1)k = 10).
SCATTER_PRIOR_DOF = 6.0

#: The grid of log τ² the posterior is integrated on (τ² from 1e-4 to 1e4).
_LOG_TAU2 = np.linspace(np.log(1e-4), np.log(1e4), 801)

#: Smallest information kept along a direction (whitened units).
_MIN_INFORMATION = 1e-9


def _symmetric(a):
    return 0.5 * (a + np.swapaxes(a, -1, -2))


@dataclass(frozen=True)
class Direction:
    """A combination of geometry parameters and the batch mean along it.

    Attributes
    ----------
    name : str
        In words (:func:`~reflector_opt.asbuilt._uncertainty.direction_name`).
    weights : numpy.ndarray
        Shape (g,): the unit direction in prior-std units (sign: its largest term positive).
    estimate : float
        The batch mean along it, in prior-std units (NaN where not determined).
    std : float
        Its standard uncertainty, prior-std units: the scatter's, the identifications' and
        (if given) the model form's together, the prior divided out (∞ where not determined).
    ratio : float
        Posterior over prior std along it: of the batch mean, ``std/√(1 + std²)``, for a
        direction the data determine; of the pooled identifications for one they leave open.
    model_form : float
        The part of ``std`` that is the identification's model-form uncertainty, prior-std
        units (0 when none was given).
    reference : float
        The part of ``std`` that is the angle reference's, common to the units, prior-std
        units (0 when the identifications took the reference as exact).
    """

    name: str
    weights: np.ndarray
    estimate: float
    std: float
    ratio: float
    model_form: float = 0.0
    reference: float = 0.0

    @property
    def t(self):
        """Estimate over its std."""
        return self.estimate / self.std if self.std > 0 else float("nan")

    def to_dict(self, names):
        """JSON-ready: name, estimate, std, t, ratio, weights (named, prior-std units)."""
        weights = {n: round(float(w), 4) for n, w in zip(names, self.weights, strict=True)}
        return {
            "name": self.name,
            "estimate_prior_std": json_number(self.estimate),
            "std_prior_std": json_number(self.std),
            "t": float(self.t) if np.isfinite(self.estimate) else None,
            "posterior_prior_ratio": float(self.ratio),
            "model_form_std_prior_std": json_number(self.model_form),
            "reference_std_prior_std": json_number(self.reference),
            "weights": {n: w for n, w in weights.items() if w != 0.0},
        }


@dataclass(frozen=True, repr=False)
class BatchMean(Summarised):
    """The systematic part of a batch's printed geometry, and the scatter about it.

    Attributes
    ----------
    batch : reflector_opt.asbuilt._batch.Batch
    directions : tuple of Direction
        The combinations the batch's data determine, best known first: the batch mean along
        each (its ``ratio`` is that of the batch mean, the scatter included).
    undetermined : tuple of Direction
        The combinations the data leave open (estimate NaN; ``ratio`` that of the pooled
        identifications), best determined first.
    mean : numpy.ndarray
        Shape (g,): posterior mean of the batch-mean deviation per parameter (prior: the
        tolerance model's spread), mm and degrees.
    mean_std : numpy.ndarray
        Shape (g,): its posterior std.
    scatter_factor : float
        τ: the unit-to-unit scatter as a multiple of the tolerance model's spread.
    scatter_estimated : bool
        True when τ was estimated from the units (at least :data:`MIN_UNITS`).
    assume_systematic : bool
        The deviation of fewer than :data:`MIN_UNITS` units was taken as systematic.
    model_form : tuple of str
        Where the model-form uncertainty in the mean's comes from (empty: nowhere).
    scatter_prior : float
        The scale s₀ of the scatter's prior (:func:`scatter_variance`), a multiple of the
        tolerance model's scatter.
    """

    batch: object
    directions: tuple
    undetermined: tuple
    mean: np.ndarray
    mean_std: np.ndarray
    scatter_factor: float
    scatter_estimated: bool
    assume_systematic: bool
    model_form: tuple = ()
    scatter_prior: float = 1.0

    def _summary(self):
        """Title and (label, value) rows of :class:`BatchMean`."""
        how = "estimated" if self.scatter_estimated else "assumed"
        rows = [
            (
                "scatter factor τ",
                f"{fmt(self.scatter_factor)} ({how}, prior scale {fmt(self.scatter_prior)})",
            ),
            ("systematic assumed", "yes" if self.assume_systematic else "no"),
            ("undetermined directions", str(len(self.undetermined))),
            ("model-form uncertainty", ", ".join(self.model_form) or "none"),
        ]
        for d in self.directions[:10]:
            rows.append((d.name, f"{fmt(d.estimate)} ± {fmt(d.std)} (std ratio {fmt(d.ratio)})"))
        title = (
            f"BatchMean: {self.batch.n_units} units, {len(self.directions)} determined directions"
        )
        return title, rows

    @property
    def separable(self):
        """True when the batch has enough units to tell systematic from random."""
        return self.batch.n_units >= MIN_UNITS

    def systematic(self, applied=None):
        """The batch mean along the chosen directions, as parameter deviations.

        Parameters
        ----------
        applied : sequence of bool, optional
            Which of :attr:`directions` to include (default all).

        Returns
        -------
        (numpy.ndarray, numpy.ndarray)
            The deviation, shape (g,), mm and degrees, and its covariance (g, g).
        """
        prior = self.batch.prior_std
        applied = [True] * len(self.directions) if applied is None else list(applied)
        value, cov = np.zeros(len(prior)), np.zeros((len(prior), len(prior)))
        for direction, use in zip(self.directions, applied, strict=True):
            if use:
                vector = direction.weights * prior
                value += direction.estimate * vector
                cov += direction.std**2 * np.outer(vector, vector)
        return value, cov

    def rows(self):
        """Per parameter: batch-mean deviation, std, scatter (model and sample), share."""
        batch = self.batch
        sample = np.std(batch.deviations, axis=0, ddof=1) if batch.n_units > 1 else None
        basis = np.array([d.weights for d in self.directions]).reshape(-1, len(batch.names))
        share = np.sum(basis**2, axis=0)
        return {
            name: {
                "mean": float(self.mean[j]),
                "std": float(self.mean_std[j]),
                "prior_std": float(batch.prior_std[j]),
                "scatter": float(self.scatter_factor * batch.prior_std[j]),
                "sample_scatter": None if sample is None else float(sample[j]),
                "determined_share": float(share[j]),
            }
            for j, name in enumerate(batch.names)
        }

    def to_dict(self):
        """JSON-ready summary."""
        names = self.batch.names
        return {
            "n_units": self.batch.n_units,
            "units": list(self.batch.labels),
            "separable": self.separable,
            "assume_systematic": self.assume_systematic,
            "scatter_factor": float(self.scatter_factor),
            "scatter_estimated": self.scatter_estimated,
            "scatter_prior": {"scale": self.scatter_prior, "dof": SCATTER_PRIOR_DOF},
            "model_form": list(self.model_form),
            "parameters": self.rows(),
            "determined": [d.to_dict(names) for d in self.directions],
            "not_determined": [d.to_dict(names) for d in self.undetermined],
        }


def _whitened(batch):
    """Whitened deviations (n, g) and posterior covariances (n, g, g) of the units."""
    s = batch.prior_std
    return batch.deviations / s, _symmetric(batch.covariances / np.outer(s, s))


def _information(cov, z):
    """Per unit: the data's information matrix H (n, g, g) and vector h (n, g), whitened."""
    precision = _symmetric(np.linalg.inv(cov))
    lam, vec = np.linalg.eigh(precision - np.eye(cov.shape[-1]))
    lam = np.clip(lam, 0.0, None)
    information = np.einsum("nij,nj,nkj->nik", vec, lam, vec)
    return information, np.einsum("nij,nj->ni", precision, z)


def _about_mean(information, vector, tau2):
    """Information matrix W (g, g) and vector b (g,) about μ, scatter τ²."""
    lam, vec = np.linalg.eigh(information)
    lam = np.clip(lam, 0.0, None)
    damp = 1.0 / (1.0 + tau2 * lam)
    w = np.einsum("nij,nj,nkj->ik", vec, lam * damp, vec)
    projected = np.einsum("nji,nj->ni", vec, vector)
    b = np.einsum("nij,nj->i", vec, damp * projected)
    return _symmetric(w), b


def _undo_prior(cov, basis):
    """Per unit, in a subspace: A (n, k, k) taking a posterior mean to the data-only
    estimate (m = A·Uᵀz), and the data-only covariance S (n, k, k)."""
    marginal = _symmetric(np.einsum("ji,njl,lk->nik", basis, cov, basis))
    precision = _symmetric(np.linalg.inv(marginal))
    lam, vec = np.linalg.eigh(precision - np.eye(basis.shape[1]))
    lam = np.clip(lam, _MIN_INFORMATION, None)
    s = np.einsum("nij,nj,nkj->nik", vec, 1.0 / lam, vec)
    return s @ precision, s


def _unit_estimates(cov, z, basis):
    """Per unit, the data-only estimate m (n, k) and covariance S (n, k, k) in a subspace."""
    undo, s = _undo_prior(cov, basis)
    return np.einsum("nij,jk,nk->ni", undo, basis.T, z), s


def _gls(m, s, tau2):
    """The GLS mean, its covariance and Q for scatter τ²."""
    weights = np.linalg.inv(s + tau2 * np.eye(m.shape[1]))
    cov = _symmetric(np.linalg.inv(weights.sum(axis=0)))
    mean = cov @ np.einsum("nij,nj->i", weights, m)
    r = m - mean
    return mean, cov, float(np.einsum("ni,nij,nj->", r, weights, r))


def _restricted_log_likelihood(m, s, tau2):
    """REML log-likelihood of τ² (μ integrated out under a flat prior), up to a constant."""
    _, cov, q = _gls(m, s, tau2)
    v = s + tau2 * np.eye(m.shape[1])
    return -0.5 * (np.sum(np.linalg.slogdet(v)[1]) - np.linalg.slogdet(cov)[1] + q)


def scatter_variance(m, s, scale=1.0, dof=SCATTER_PRIOR_DOF):
    """Posterior mean of the scatter τ² under a scaled-inverse-χ² prior, whitened units.

    The model of the module docstring: ``m_u ~ N(μ, S_u + τ²I)``, μ integrated out (REML),
    ``τ² ~ Scale-Inv-χ²(ν₀ = dof, s₀² = scale²)``, whose density is
    ``∝ (τ²)^−(1 + ν₀/2) · exp(−ν₀ s₀² / (2τ²))`` (Gelman et al., *Bayesian Data Analysis*,
    3rd ed., appendix A). The posterior is integrated on a grid of log τ² (1e-4 to 1e4).

    Parameters
    ----------
    m : numpy.ndarray
        Shape (n, k): each unit's data-only estimate in the subspace, prior-std units.
    s : numpy.ndarray
        Shape (n, k, k): its covariance.
    scale : float
        s₀: the prior's scale, as a multiple of the tolerance model's scatter (default 1).
    dof : float
        ν₀: the prior's degrees of freedom (default :data:`SCATTER_PRIOR_DOF`).

    Returns
    -------
    float
        E[τ²], in units of the tolerance model's variance.
    """
    tau2 = np.exp(_LOG_TAU2)
    log_prior = -(1.0 + 0.5 * dof) * _LOG_TAU2 - 0.5 * dof * scale**2 / tau2
    log_post = np.array([_restricted_log_likelihood(m, s, t) for t in tau2])
    log_post += log_prior + _LOG_TAU2  # the grid is uniform in log τ²: dτ² = τ² d(log τ²)
    weight = np.exp(log_post - log_post.max())
    return float(np.sum(weight * tau2) / np.sum(weight))


def _subspace(w):
    """Eigen-directions of W (columns, strongest first), κ, and the determined mask."""
    kappa, vec = np.linalg.eigh(w)
    order = np.argsort(-kappa)
    kappa, vec = np.clip(kappa[order], 0.0, None), vec[:, order]
    return vec, kappa, kappa >= 1.0 / DETERMINED_RATIO**2 - 1.0


def _scatter_factor(cov, z, information, scale):
    """τ² estimated where each unit's own data determine its deviation, or None if nowhere.

    The subspace is that of the units' mean information Σ H_u / n (κ ≥ 3), so that the
    estimate does not depend on the scatter it estimates.
    """
    vec, _, determined = _subspace(information.mean(axis=0))
    if not determined.any():
        return None
    return scatter_variance(*_unit_estimates(cov, z, vec[:, determined]), scale=scale)


def _discrepancy(batch, model_form, basis, cov):
    """The model-form covariance of the batch mean in the coordinates of ``basis`` (k, k).

    The part the files record — a covariance of posterior means, taken to the data-only
    estimates as the units' are (A Uᵀ Σ U Aᵀ), averaged over the units: one term, common to
    them all — plus ``Σ_k b_k b_kᵀ`` of simulated biases if given.
    """
    form = np.zeros((basis.shape[1], basis.shape[1]))
    if batch.systematic is not None:
        s = batch.prior_std
        recorded = _symmetric(batch.systematic / np.outer(s, s))
        undo, _ = _undo_prior(cov, basis)
        inner = np.einsum("ji,njl,lk->nik", basis, recorded, basis)
        form += _symmetric(np.einsum("nij,njl,nkl->ik", undo, inner, undo) / len(undo))
    if model_form is not None:
        z, cov = _whitened(model_form)
        bias, _ = _unit_estimates(cov, z, basis)
        form += bias.T @ bias
    return form


def _reference_split(batch, cov, basis, s):
    """The units' data-only covariances with their reference known (n, k, k), and the
    reference's part of them averaged over the units (k, k): zero without reference."""
    if batch.reference is None:
        return s, np.zeros(s.shape[1:])
    scale = batch.prior_std
    _, given = _undo_prior(cov - _symmetric(batch.reference / np.outer(scale, scale)), basis)
    lam, vec = np.linalg.eigh(_symmetric((s - given).mean(axis=0)))
    return given, (vec * np.clip(lam, 0.0, None)) @ vec.T


def _directions(batch, basis, cov, z, tau2, model_form):
    """The batch mean along its independent directions in D, best determined first."""
    m, s = _unit_estimates(cov, z, basis)
    given, reference = _reference_split(batch, cov, basis, s)
    mean, mean_cov, _ = _gls(m, given, tau2)
    form = _discrepancy(batch, model_form, basis, cov)
    mean_cov = mean_cov + form + reference
    variance, rotation = np.linalg.eigh(mean_cov)
    out = []
    for k in np.argsort(variance):
        weights = basis @ rotation[:, k]
        sign = np.sign(weights[np.argmax(np.abs(weights))])
        std = float(np.sqrt(max(variance[k], 0.0)))
        out.append(
            Direction(
                direction_name(weights, batch.names, batch.words),
                weights * sign,
                float(sign * rotation[:, k] @ mean),
                std,
                std / np.sqrt(1.0 + std**2),
                float(np.sqrt(max(rotation[:, k] @ form @ rotation[:, k], 0.0))),
                float(np.sqrt(max(rotation[:, k] @ reference @ rotation[:, k], 0.0))),
            )
        )
    return out


def _open_directions(batch, w):
    """The eigen-directions of W the batch leaves open, named, best determined first."""
    vec, kappa, determined = _subspace(w)
    out = []
    for k in np.flatnonzero(~determined):
        weights = vec[:, k] * np.sign(vec[np.argmax(np.abs(vec[:, k])), k])
        name = direction_name(weights, batch.names, batch.words)
        nan = float("nan")
        out.append(Direction(name, weights, nan, float("inf"), 1 / np.sqrt(1 + kappa[k]), nan, nan))
    return out


def _form_sources(batch, model_form):
    """Where the model-form uncertainty comes from, in words (empty: nowhere)."""
    out = []
    if batch.systematic is not None and np.any(batch.systematic):
        out.append("the identification files")
    if model_form is not None:
        out += [f"simulated {label}" for label in model_form.labels]
    return tuple(out)


def pool(batch, assume_systematic=False, model_form=None, scatter_prior=1.0):
    """The batch mean of a batch's geometry deviations, its uncertainty, and the scatter.

    Parameters
    ----------
    batch : reflector_opt.asbuilt._batch.Batch
    assume_systematic : bool
        With fewer than :data:`MIN_UNITS` units, take their deviation as systematic (no
        scatter); otherwise the prior's scale is assumed. Ignored with more units
        (the scatter is estimated).
    model_form : reflector_opt.asbuilt._batch.Batch, optional
        The identification's model-form biases, simulated, one "unit" per effect
        (:func:`reflector_opt.asbuilt._model_form_bias.model_form_bias`): ``Σ_k b_k b_kᵀ`` is added
        to the batch mean's covariance — besides the model-form term the identification
        files record (``batch.systematic``), which is always added once. Give it only for
        files that record none.
    scatter_prior : float
        The scale s₀ of the scatter's prior, a multiple of the tolerance model's scatter
        (default 1; :func:`scatter_variance`); also the scatter assumed where it is not
        estimated.

    Returns
    -------
    BatchMean
    """
    if not (np.isfinite(scatter_prior) and 0.0 < scatter_prior <= 100.0):
        raise InputError(f"scatter_prior: expected a number in (0, 100], got {scatter_prior!r}")
    z, cov = _whitened(batch)
    information, vector = _information(cov, z)
    few = batch.n_units < MIN_UNITS
    estimated = None if few else _scatter_factor(cov, z, information, scatter_prior)
    assumed = 0.0 if assume_systematic and few else scatter_prior**2
    tau2 = assumed if estimated is None else estimated
    seen = information.sum(axis=0)
    vec, _, determined = _subspace(seen)
    directions = []
    if determined.any():
        directions = _directions(batch, vec[:, determined], cov, z, tau2, model_form)
    w, b = _about_mean(information, vector, tau2)
    posterior = _symmetric(np.linalg.inv(np.eye(len(b)) + w))
    return BatchMean(
        batch=batch,
        directions=tuple(directions),
        undetermined=tuple(_open_directions(batch, seen)),
        mean=(posterior @ b) * batch.prior_std,
        mean_std=np.sqrt(np.clip(np.diag(posterior), 0.0, None)) * batch.prior_std,
        scatter_factor=float(np.sqrt(tau2)),
        scatter_estimated=estimated is not None,
        assume_systematic=bool(assume_systematic and few),
        model_form=_form_sources(batch, model_form),
        scatter_prior=float(scatter_prior),
    )
