"""The print correction: pre-compensate the next print by the batch's systematic deviation.

A printer that moves the sphere centre by +40 µm every time prints the part right if the
drawing moves it by −40 µm first. :func:`plan_correction` decides, from a batch mean
(:func:`reflector_opt.asbuilt._pooling.pool`), how much to pre-compensate along each of its
independent directions i (estimate m_i, standard uncertainty s_i — scatter, identification,
model form and angle reference together — and t_i = m_i/s_i, in tolerance-spread units):

* only along the directions the batch **determines** (posterior/prior std ratio ≤ 0.5,
  :class:`~reflector_opt.asbuilt._pooling.Direction`) — what the data cannot separate, e.g. a
  seat tilt that barely changes the light, is left as drawn and named;
* only along the directions where the batch mean is **resolved**: s_i at most ``max_std``
  of the tolerance spread. A correction leaves its own uncertainty behind; where that
  exceeds the spread a print deviation typically has it can add more error than it removes;
* by the **shrinkage factor** ``a_i = max(0, 1 − (level/t_i)²)`` of the estimate: the
  posterior mean of the systematic part μ_i under a normal prior N(0, σ_i²) whose variance is
  estimated from the direction itself, ``σ̂_i² = max(0, m_i² − level²·s_i²)``
  (``a_i = σ̂_i²/(σ̂_i² + level²·s_i²)``, positive-part James–Stein with the noise variance
  counted ``level²`` times). Under a squared loss of the deviation left in the next batch the
  posterior mean is the correction of least expected loss; the factor rises smoothly from 0
  at ``|t| = level`` (no systematic part shown: nothing changed) through 0.56 at ``1.5·level``
  to 0.94 at ``4·level``, in place of the all-or-nothing ``|t| > level`` gate of before.

The **step** α ∈ [0, 1] along this correction is then chosen by what the user loses —
the next batch's expected worst-case angle error and margins over the posterior of the batch
mean (:mod:`reflector_opt.asbuilt._stepsearch`) — and cut back until the part the process is
predicted to print keeps every constraint (:meth:`Correction.with_step` records it and what
was given up).

The change is ``−α Σ_i a_i m_i v_i`` (v_i the direction in parameter units), applied to the
design's printed geometry in the identification's own terms
(:meth:`reflector_opt.asbuilt._parameters.ParameterLayout.unit_design`: the reflecting sphere's
radius and centre, each sensor seat's standoff, shifts and tilts in its own frame); the read-out
(gain, offset) and the surface are not printed and are never changed.
:func:`corrected_design` gives the design to print next, with a ``correction`` block that
records what was changed, by how much, its uncertainty and which files and units it came
from.

**Correcting twice from the same data is refused**, not made idempotent: a design whose
``correction`` block (or an earlier one it carries in ``previous``) lists an identification
by the same SHA-256 cannot be corrected from it again (:func:`check_not_applied`). A design
corrected from one batch is corrected further only from units printed from it.
"""

from dataclasses import dataclass, replace

import numpy as np
from scipy.stats import chi2

from reflector_opt.asbuilt._parameters import ParameterLayout
from reflector_opt.util._display import Summarised, fmt
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import json_number

CORRECTION_FORMAT = "reflector-opt/correction@1"

#: Default level of the shrinkage: a direction is changed only where ``|t|`` exceeds it, by
#: the factor ``1 − (level/t)²``.
LEVEL = 2.0

#: Default confidence of the χ² test of the resolved directions as a whole (reported).
CONFIDENCE = 0.95

#: Default largest uncertainty of a correctable direction, tolerance-spread units: a
#: correction known less well than the print's own tolerance can add more error than it
#: removes.
MAX_STD = 1.0


@dataclass(frozen=True, repr=False)
class Correction(Summarised):
    """What to change in the drawing, and why.

    Attributes
    ----------
    mean : reflector_opt.asbuilt._pooling.BatchMean
        The batch mean it is based on.
    factors : tuple of float
        Per determined direction (``mean.directions``), the shrinkage factor a_i in [0, 1)
        of its estimate (:func:`shrinkage_factors`; 0: left as drawn).
    chi2 : float
        χ² of the batch mean over the resolved directions (reported, not a gate).
    threshold : float
        The χ²_k quantile it is compared with.
    level : float
        The shrinkage's level: a direction changes only where ``|t|`` exceeds it.
    confidence : float
        Confidence of the χ² test.
    resolved : tuple of bool
        Per determined direction, whether the batch mean is known along it to within
        ``max_std`` (only those can be corrected).
    max_std : float
        The largest std of a resolved direction, tolerance-spread units.
    step : float
        α: the share of the shrunk correction applied (chosen by expected loss and cut back
        for the constraints, :mod:`reflector_opt.asbuilt._stepsearch`; default 1).
    given_up : tuple of str
        What the step gave up and why, in words (empty: nothing).
    """

    mean: object
    factors: tuple
    chi2: float
    threshold: float
    level: float
    confidence: float
    resolved: tuple = ()
    max_std: float = 1.0
    step: float = 1.0
    given_up: tuple = ()

    def _summary(self):
        return _summary(self)

    @property
    def dof(self):
        """The number of resolved directions (the χ² test's degrees of freedom)."""
        return sum(self.resolved)

    @property
    def significant(self):
        """True when the batch mean over the resolved directions is significant."""
        return self.dof > 0 and self.chi2 > self.threshold

    @property
    def applied(self):
        """Per determined direction, whether the drawing changes along it."""
        return tuple(bool(self.step * a > 0.0) for a in self.factors)

    @property
    def change(self):
        """The change to the drawn geometry, per parameter of ``mean.batch.names``, mm/deg."""
        return -self.step * self.full_change

    @property
    def full_change(self):
        """The shrunk correction at step 1 (before the expected loss and the constraints)."""
        prior = self.mean.batch.prior_std
        out = np.zeros(len(prior))
        for direction, a in zip(self.mean.directions, self.factors, strict=True):
            out += a * direction.estimate * direction.weights * prior
        return out

    @property
    def change_covariance(self):
        """Covariance of :attr:`change`, (g, g): each direction's std times its factor."""
        prior = self.mean.batch.prior_std
        cov = np.zeros((len(prior), len(prior)))
        for direction, a in zip(self.mean.directions, self.factors, strict=True):
            vector = direction.weights * prior
            cov += (self.step * a * direction.std) ** 2 * np.outer(vector, vector)
        return cov

    @property
    def changes_anything(self):
        """True when at least one direction is corrected."""
        return any(self.applied)

    def with_step(self, step, given_up=()):
        """The same correction applied by the share ``step`` (α), recording what was given up.

        Parameters
        ----------
        step : float
            α in [0, 1].
        given_up : sequence of str
            What was given up, in words.

        Returns
        -------
        Correction
        """
        if not (np.isfinite(step) and 0.0 <= step <= 1.0):
            raise InputError(f"step: expected a number in [0, 1], got {step!r}")
        return replace(self, step=float(step), given_up=tuple(given_up))

    def rows(self):
        """Per geometry parameter: the change, its std and the determined share."""
        rows = self.mean.rows()
        change, cov = self.change, self.change_covariance
        std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
        return {
            name: {
                "change": float(change[j]),
                "std": float(std[j]),
                "determined_share": rows[name]["determined_share"],
            }
            for j, name in enumerate(self.mean.batch.names)
        }

    def to_dict(self):
        """JSON-ready: the rule, the directions (factor, applied), the step, the changes."""
        names = self.mean.batch.names
        directions = [
            {
                **direction.to_dict(names),
                "resolved": bool(resolved),
                "factor": float(a),
                "applied": bool(applied),
            }
            for direction, a, resolved, applied in zip(
                self.mean.directions, self.factors, self.resolved, self.applied, strict=True
            )
        ]
        return {
            "test": {
                "chi2": float(self.chi2),
                "dof": self.dof,
                "threshold": json_number(self.threshold),
                "confidence": self.confidence,
                "level": self.level,
                "max_std_prior_std": self.max_std,
                "significant": self.significant,
            },
            "rule": "factor max(0, 1 - (level/t)^2) per resolved direction, times the step",
            "step": self.step,
            "given_up": list(self.given_up),
            "directions": directions,
            "changed": {name: row for name, row in self.rows().items() if abs(row["change"]) > 0.0},
            "not_determined": [d.name for d in self.mean.undetermined],
        }


def shrinkage_factors(t, resolved, level=LEVEL):
    """The shrinkage factor of each direction's estimate: ``max(0, 1 − (level/t)²)``.

    The posterior mean of a systematic part μ measured as m ~ N(μ, s²), under the prior
    N(0, σ̂²) with ``σ̂² = max(0, m² − level²·s²)`` estimated from the direction itself
    (positive-part James–Stein; Efron & Morris 1973), is ``σ̂²/(σ̂² + level²·s²)·m``:
    the factor is 0 for ``|t| ≤ level`` and tends to 1 as ``|t|`` grows.

    Parameters
    ----------
    t : array_like
        Estimate over its std, per direction.
    resolved : array_like of bool
        Per direction, whether it may be corrected at all (0 where not).
    level : float
        The level (default 2).

    Returns
    -------
    numpy.ndarray
        The factors, in [0, 1).
    """
    t = np.asarray(t, dtype=float)
    ok = np.asarray(resolved, dtype=bool) & np.isfinite(t) & (np.abs(t) > level)
    safe = np.where(ok, t, 1.0)
    return np.where(ok, 1.0 - (level / safe) ** 2, 0.0)


def plan_correction(mean, level=LEVEL, confidence=CONFIDENCE, max_std=MAX_STD):
    """The shrunk correction of a batch mean, at step 1 (:func:`shrinkage_factors`).

    Parameters
    ----------
    mean : reflector_opt.asbuilt._pooling.BatchMean
    level : float
        The shrinkage's level (default 2): a resolved direction changes where ``|t|``
        exceeds it, by the factor ``1 − (level/t)²``.
    confidence : float
        Confidence of the reported χ² test of the resolved directions (default 0.95).
    max_std : float
        A determined direction is resolved when the batch mean's std along it is at most
        this, in tolerance-spread units (default 1).

    Returns
    -------
    Correction
    """
    if not (np.isfinite(level) and 0 < level <= 10):
        raise InputError(f"level: expected a number in (0, 10], got {level!r}")
    if not 0 < confidence < 1:
        raise InputError(f"confidence: expected between 0 and 1, got {confidence!r}")
    if not (np.isfinite(max_std) and max_std > 0):
        raise InputError(f"max_std: expected a positive number, got {max_std!r}")
    resolved = np.array([d.std <= max_std for d in mean.directions], dtype=bool)
    t = np.array([d.t for d in mean.directions])
    k = int(resolved.sum())
    return Correction(
        mean=mean,
        factors=tuple(shrinkage_factors(t, resolved, level).tolist()),
        chi2=float(np.sum(t[resolved] ** 2)),
        threshold=float(chi2.ppf(confidence, k)) if k else float("inf"),
        level=float(level),
        confidence=float(confidence),
        resolved=tuple(resolved.tolist()),
        max_std=float(max_std),
    )


def _digests(block):
    """Every identification digest a correction block (and its earlier ones) lists."""
    found = set()
    for entry in [block, *block.get("previous", [])]:
        for source in entry.get("sources", []):
            if isinstance(source, dict) and isinstance(source.get("sha256"), str):
                found.add(source["sha256"])
    return found


def check_not_applied(design, batch, name="the design"):
    """Refuse to correct a design again from identifications it was corrected from.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    batch : reflector_opt.asbuilt._batch.Batch
    name : str
        The design's name in the message (e.g. its file).

    Raises
    ------
    InputError
    """
    done = _digests(design.correction)
    for source in batch.sources:
        if source.digest in done:
            what = source.file or "this identification"
            raise InputError(
                f"{name} is already corrected from {what}; correcting twice from the same "
                "units is refused — identify units printed from the corrected design instead"
            )


def changed_geometry(design, names, change):
    """The design with its printed geometry changed by ``change``, in the identification's terms.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    names : sequence of str
        Geometry parameters (:func:`~reflector_opt.asbuilt._batch.geometry_names`).
    change : array_like
        Their changes, mm and degrees
        (:meth:`~reflector_opt.asbuilt._parameters.ParameterLayout.unit_design`).

    Returns
    -------
    reflector_opt.design._design.Design
        Raises InputError if the geometry is not a valid design.
    """
    layout = ParameterLayout(design, 1)
    x = np.zeros(layout.size)
    block = x[layout.unit_slice(0)]
    for name, value in zip(names, change, strict=True):
        block[layout.unit_names.index(name)] = value
    built, _ = layout.unit_design(x, 0)
    return built


def correction_block(correction, design, prediction=None):
    """The ``correction`` block of the corrected design.

    Parameters
    ----------
    correction : Correction
    design : reflector_opt.design._design.Design
        The design corrected (its own block, if any, goes to ``previous``).
    prediction : dict, optional
        The next batch predicted with and without the correction
        (:func:`reflector_opt.asbuilt._batchforecast.predict_next_batch`), recorded.

    Returns
    -------
    dict
    """
    mean = correction.mean
    batch = mean.batch
    previous = []
    if design.correction:
        earlier = dict(design.correction)
        previous = [*earlier.pop("previous", []), earlier]
    return {
        "format": CORRECTION_FORMAT,
        "batch": batch.batch,
        "sources": [s.to_dict() for s in batch.sources],
        "n_units": batch.n_units,
        "assume_systematic": mean.assume_systematic,
        "scatter_factor": mean.scatter_factor,
        "scatter_estimated": mean.scatter_estimated,
        **correction.to_dict(),
        "prediction": prediction,
        "previous": previous,
    }


def corrected_design(design, correction, prediction=None):
    """The design to print next: the correction applied, and recorded.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        The design the batch was printed from.
    correction : Correction
    prediction : dict, optional
        Recorded in the block (:func:`correction_block`).

    Returns
    -------
    reflector_opt.design._design.Design
        Its ``correction`` block records the change (:func:`correction_block`).

    Raises
    ------
    InputError
        The corrected geometry is not a valid design (naming the constraint it breaks).
    """
    batch = correction.mean.batch
    try:
        built = changed_geometry(design, batch.names, correction.change)
    except InputError as exc:
        raise InputError(f"the corrected design cannot be built: {exc}") from None
    return built.replace(correction=correction_block(correction, design, prediction))


def _summary(c):
    """Title and (label, value) rows of :class:`Correction`."""
    rows = [
        ("χ² of the batch mean", f"{fmt(c.chi2)} (threshold {fmt(c.threshold)}, {c.dof} dof)"),
        ("significant", "yes" if c.significant else "no"),
        ("confidence", fmt(c.confidence)),
        ("shrinkage level", fmt(c.level)),
        ("resolved directions", f"{sum(c.resolved)} (std ≤ {fmt(c.max_std)})"),
        ("step", fmt(c.step)),
    ]
    for direction, a, applied in zip(c.mean.directions[:10], c.factors, c.applied, strict=False):
        rows.append(
            (
                direction.name,
                f"{f'corrected by {fmt(a * c.step)}' if applied else 'kept'}, "
                f"estimate {fmt(direction.estimate)} ± {fmt(direction.std)}",
            )
        )
    return f"Correction: {sum(c.applied)} of {len(c.applied)} directions corrected", rows
