"""The print correction: pre-compensate the next print by the batch's systematic deviation.

A printer that moves the sphere centre by +40 µm every time prints the part right if the
drawing moves it by −40 µm first. :func:`plan_correction` decides, from a batch mean
(:func:`reflector_opt.asbuilt.pooling.pool`), what to pre-compensate:

* only along the directions the batch **determines** (posterior/prior std ratio ≤ 0.5,
  :class:`~reflector_opt.asbuilt.pooling.Direction`) — what the data cannot separate, e.g. a
  seat tilt that barely changes the light, is left as drawn and named;
* only along the directions where the batch mean is **resolved**: its standard uncertainty
  (scatter, identification and model form together) at most ``max_std`` of the tolerance
  spread. A correction is applied unbiased, so it leaves its own uncertainty behind; where
  that exceeds the spread a print deviation typically has — along the sphere centre's
  height, in the default design, which the identification's model-form bias blurs by about
  two spreads — it can add more error than it removes;
* only if the systematic part is **significant**: the batch mean along the resolved
  directions as a whole (χ² of its k components above the ``confidence`` quantile of χ²_k)
  and along each direction on its own (``|t|`` > ``level``). Without a systematic deviation the
  correction therefore changes nothing, at the stated confidence; whatever it changes is
  more than ``level`` times its own uncertainty.

The change is the negative of the batch mean along the chosen directions, applied to the
design's printed geometry in the identification's own terms
(:meth:`reflector_opt.asbuilt.parameters.Layout.unit_design`: the reflecting sphere's radius
and centre, each sensor seat's standoff, shifts and tilts in its own frame); the read-out
(gain, offset) and the surface are not printed and are never changed.
:func:`corrected_design` gives the design to print next, with a ``correction`` block that
records what was changed, by how much, its uncertainty and which files and units it came
from.

**Correcting twice from the same data is refused**, not made idempotent: a design whose
``correction`` block (or an earlier one it carries in ``previous``) lists an identification
by the same SHA-256 cannot be corrected from it again (:func:`check_not_applied`). A design
corrected from one batch is corrected further only from units printed from it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

from reflector_opt.asbuilt.parameters import Layout
from reflector_opt.util.display import fmt, html_summary, text_summary
from reflector_opt.util.errors import InputError

__all__ = [
    "CORRECTION_FORMAT",
    "Correction",
    "check_not_applied",
    "corrected_design",
    "plan_correction",
]

CORRECTION_FORMAT = "reflector-opt/correction@1"

#: Default significance of each direction: ``|t|`` above this.
LEVEL = 2.0

#: Default confidence of the test of the resolved directions as a whole.
CONFIDENCE = 0.95

#: Default largest uncertainty of a correctable direction, tolerance-spread units: a
#: correction known less well than the print's own tolerance can add more error than it
#: removes.
MAX_STD = 1.0


@dataclass(frozen=True)
class Correction:
    """What to change in the drawing, and why.

    Attributes
    ----------
    mean : reflector_opt.asbuilt.pooling.BatchMean
        The batch mean it is based on.
    applied : tuple of bool
        Per determined direction (``mean.directions``), whether it is corrected.
    chi2 : float
        χ² of the batch mean over the determined subspace.
    threshold : float
        The χ²_k quantile it is compared with.
    level : float
        Per-direction threshold on ``|t|``.
    confidence : float
        Confidence of the test of the resolved directions as a whole.
    resolved : tuple of bool
        Per determined direction, whether the batch mean is known along it to within
        ``max_std`` (only those can be corrected).
    max_std : float
        The largest std of a resolved direction, tolerance-spread units.
    """

    mean: object
    applied: tuple
    chi2: float
    threshold: float
    level: float
    confidence: float
    resolved: tuple = ()
    max_std: float = 1.0

    def __repr__(self):
        return text_summary(*_summary(self))

    def _repr_html_(self):
        return html_summary(*_summary(self))

    @property
    def dof(self):
        """The number of resolved directions (the χ² test's degrees of freedom)."""
        return sum(self.resolved)

    @property
    def significant(self):
        """True when the batch mean over the resolved directions is significant."""
        return self.dof > 0 and self.chi2 > self.threshold

    @property
    def change(self):
        """The change to the drawn geometry, per parameter of ``mean.batch.names``, mm/deg."""
        return -self.mean.systematic(self.applied)[0]

    @property
    def change_covariance(self):
        """Covariance of :attr:`change`, (g, g)."""
        return self.mean.systematic(self.applied)[1]

    @property
    def changes_anything(self):
        """True when at least one direction is corrected."""
        return any(self.applied)

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
        """JSON-ready: the test, the directions (applied or not), the changes."""
        names = self.mean.batch.names
        directions = []
        for direction, applied, resolved in zip(
            self.mean.directions, self.applied, self.resolved, strict=True
        ):
            directions.append(
                {**direction.to_dict(names), "resolved": bool(resolved), "applied": bool(applied)}
            )
        return {
            "test": {
                "chi2": float(self.chi2),
                "dof": self.dof,
                "threshold": float(self.threshold),
                "confidence": self.confidence,
                "level": self.level,
                "max_std_prior_std": self.max_std,
                "significant": self.significant,
            },
            "directions": directions,
            "changed": {name: row for name, row in self.rows().items() if abs(row["change"]) > 0.0},
            "not_determined": [d.name for d in self.mean.undetermined],
        }


def plan_correction(mean, level=LEVEL, confidence=CONFIDENCE, max_std=MAX_STD):
    """Choose what to pre-compensate from a batch mean.

    Parameters
    ----------
    mean : reflector_opt.asbuilt.pooling.BatchMean
    level : float
        A resolved direction is corrected when ``|t|`` exceeds it (default 2).
    confidence : float
        Confidence of the test of the resolved directions as a whole (default 0.95).
    max_std : float
        A determined direction is resolved when the batch mean's std along it is at most
        this, in tolerance-spread units (default 1).

    Returns
    -------
    Correction
    """
    if not (np.isfinite(level) and level >= 0):
        raise InputError(f"level: expected a number ≥ 0, got {level!r}")
    if not 0 < confidence < 1:
        raise InputError(f"confidence: expected between 0 and 1, got {confidence!r}")
    if not (np.isfinite(max_std) and max_std > 0):
        raise InputError(f"max_std: expected a positive number, got {max_std!r}")
    resolved = np.array([d.std <= max_std for d in mean.directions], dtype=bool)
    t = np.array([d.t for d in mean.directions])
    value = float(np.sum(t[resolved] ** 2))
    k = int(resolved.sum())
    threshold = float(chi2.ppf(confidence, k)) if k else float("inf")
    significant = k > 0 and value > threshold
    applied = tuple(
        bool(significant and r and abs(x) > level) for r, x in zip(resolved, t, strict=True)
    )
    return Correction(
        mean=mean,
        applied=applied,
        chi2=value,
        threshold=threshold,
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
    design : reflector_opt.design.design.Design
    batch : reflector_opt.asbuilt.batch.Batch
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


def _geometry(design, names, change):
    """The design with its printed geometry changed by ``change`` (Layout's terms)."""
    layout = Layout(design, 1)
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
    design : reflector_opt.design.design.Design
        The design corrected (its own block, if any, goes to ``previous``).
    prediction : dict, optional
        The next batch predicted with and without the correction
        (:func:`reflector_opt.asbuilt.nextbatch.predict_next_batch`), recorded.

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
    design : reflector_opt.design.design.Design
        The design the batch was printed from.
    correction : Correction
    prediction : dict, optional
        Recorded in the block (:func:`correction_block`).

    Returns
    -------
    reflector_opt.design.design.Design
        Its ``correction`` block records the change (:func:`correction_block`).

    Raises
    ------
    InputError
        The corrected geometry is not a valid design (naming the constraint it breaks).
    """
    batch = correction.mean.batch
    try:
        built = _geometry(design, batch.names, correction.change)
    except InputError as exc:
        raise InputError(f"the corrected design cannot be built: {exc}") from None
    return built.replace(correction=correction_block(correction, design, prediction))


def _summary(c):
    """Title and (label, value) rows of :class:`Correction`."""
    rows = [
        ("χ² of the batch mean", f"{fmt(c.chi2)} (threshold {fmt(c.threshold)}, {c.dof} dof)"),
        ("significant", "yes" if c.significant else "no"),
        ("confidence", fmt(c.confidence)),
        ("per-direction |t| level", fmt(c.level)),
        ("resolved directions", f"{sum(c.resolved)} (std ≤ {fmt(c.max_std)})"),
    ]
    for direction, applied in list(zip(c.mean.directions, c.applied, strict=False))[:10]:
        rows.append(
            (
                direction.name,
                f"{'corrected' if applied else 'kept'}, "
                f"estimate {fmt(direction.estimate)} ± {fmt(direction.std)}",
            )
        )
    return f"Correction: {sum(c.applied)} of {len(c.applied)} directions corrected", rows
