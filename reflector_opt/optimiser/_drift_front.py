"""Pareto front of white-noise resolution against drift sensitivity.

The white-noise optimum reads small voltage changes best, and so reads a drift of the light
path — LED output and detector gain move a few tenths of a percent per kelvin — as a large
angle: it is the most sensitive design to temperature. The front shows what geometry can
trade. Its x is the common drift, the angle error of a 1 % change of every sensor's light path
(:func:`~reflector_opt.optimiser._conditions.common_drift_deg`: RMS over the workspace, the
worse angle, on the budget's 1° grid); its y the white-noise objective (the worst-case 1σ
resolution with the isotropy factor, on the workspace grid). It is traced by the
ε-constraint method: the white-noise optimum first, its drift d₀; then the optimiser rerun
with the drift held at most f·d₀ for each fraction f, from the loosest limit down, each run
warm-started from the verified design of least drift found so far (the design optimised in the
conditions among them, when given). A design that meets a limit is a candidate
of that level whichever run found it, so a level keeps the best verified design that meets it
— its own, another level's, or the one optimised in the conditions — and says which
(``kept_from``): the search is a heuristic and its verification can fail (a drift limit pushes
the design towards the uniqueness limit, which the polish does not see). A level no known
design meets is recorded as infeasible with its run's reason. A point another beats on both
axes is marked dominated and left out of the front.

In operating conditions, every design of the front also gets its worst-case total error in
them (:attr:`~reflector_opt.analysis._budget.ErrorBudget.worst_case_deg`, 1° grid): how far
trading resolution for drift goes towards the error in use.
"""

import dataclasses
import functools
import math
from dataclasses import dataclass

from reflector_opt.analysis._budget import error_budget
from reflector_opt.optimiser._conditions import common_drift_deg
from reflector_opt.optimiser._evaluation import objective_value
from reflector_opt.optimiser._studies import optimise_variants
from reflector_opt.util._display import Summarised, fmt
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import json_record
from reflector_opt.util._progress import scaled

#: Default drift limits, as fractions of the white-noise optimum's drift.
DEFAULT_DRIFT_FRACTIONS = (0.9, 0.8, 0.7, 0.6, 0.5, 0.4)


@dataclass(frozen=True)
class DriftPoint:
    """One design of the drift front, or a limit no design meets.

    Attributes
    ----------
    drift_limit_deg : float or None
        The drift the optimiser had to keep below, degrees per 1 % (None: the white-noise
        optimum, unconstrained).
    feasible : bool
        False if no design meets the limit (the other figures are then NaN or None).
    drift_deg : float
        The design's common drift, degrees per 1 % (RMS, the worse angle, 1° grid).
    objective_deg : float
        Its white-noise objective on the workspace grid, degrees.
    worst_pitch_deg, worst_roll_deg : float
        Its worst-case 1σ resolution, degrees.
    worst_case_deg : float
        Its worst-case total error in the front's conditions, degrees (NaN without them).
    dominated : bool
        Another point is at least as good on both axes and better on one.
    values : dict or None
        The design variables.
    reason : str or None
        Why this level's own optimisation found no design (infeasible, or ``kept_from``
        another design).
    kept_from : str or None
        Where the design comes from when it is not this level's own optimisation's:
        ``"white-noise optimum"``, ``"drift ≤ …°"`` (another level's) or
        ``"optimised in the conditions"``.
    """

    drift_limit_deg: float | None
    feasible: bool
    drift_deg: float = math.nan
    objective_deg: float = math.nan
    worst_pitch_deg: float = math.nan
    worst_roll_deg: float = math.nan
    worst_case_deg: float = math.nan
    dominated: bool = False
    values: dict | None = None
    reason: str | None = None
    kept_from: str | None = None

    @property
    def label(self):
        """How the front names the design this level optimised."""
        if self.drift_limit_deg is None:
            return "white-noise optimum"
        return f"drift ≤ {self.drift_limit_deg:.3g}°"

    def to_dict(self):
        """JSON-ready record (NaN as null)."""
        return json_record(self)


@dataclass(frozen=True, repr=False)
class DriftFront(Summarised):
    """The levels of the drift front, the white-noise optimum first.

    Attributes
    ----------
    points : tuple of DriftPoint
    seed : int
    conditions : dict or None
        The conditions each design's ``worst_case_deg`` is in (the ``[conditions]`` table).
    reference : DriftPoint or None
        The design optimised for those conditions, on the same axes (not a level of the
        front: it minimises the total error, not the resolution at a drift).
    """

    points: tuple
    seed: int
    conditions: dict | None = None
    reference: DriftPoint | None = None

    @property
    def front_points(self):
        """The feasible, non-dominated points, in increasing drift."""
        kept = [p for p in self.points if p.feasible and not p.dominated]
        return tuple(sorted(kept, key=lambda p: p.drift_deg))

    def to_dict(self):
        """JSON-ready document (``drift_front.json``)."""
        return {
            "format": "reflector-opt/drift-front@1",
            "x": "common drift: angle error per 1 % change of every light path, RMS over the "
            "workspace, the worse angle, degrees",
            "y": "white-noise objective: worst-case 1σ resolution with the isotropy factor, "
            "degrees",
            "seed": self.seed,
            "conditions": self.conditions,
            "points": [p.to_dict() for p in self.points],
            "reference": None if self.reference is None else self.reference.to_dict(),
        }

    def _summary(self):
        """Title and (label, value) rows of :class:`DriftFront`."""
        rows = [(p.label, _describe(p)) for p in self.points]
        if self.reference is not None:
            rows.append(("optimised in the conditions", _describe(self.reference)))
        title = (
            f"DriftFront: {len(self.points)} levels, {len(self.front_points)} on the front, "
            f"seed {self.seed}"
        )
        return title, rows


def front_point(result, limit, problem):
    """The front's record of an optimised design.

    Parameters
    ----------
    result : reflector_opt.optimiser._result.OptimisationResult
    limit : float or None
        The drift limit it was optimised under, degrees per 1 %.
    problem : reflector_opt.optimiser._problem.Problem
        Its isotropy weight gives the white-noise objective, its conditions (if any) the
        worst-case total error.

    Returns
    -------
    DriftPoint
    """
    design = result.evaluation.design
    metrics = result.metrics
    conditions = problem.conditions
    total = math.nan if conditions is None else error_budget(design, conditions).worst_case_deg
    return DriftPoint(
        drift_limit_deg=limit,
        feasible=True,
        drift_deg=common_drift_deg(design),
        objective_deg=objective_value(metrics, problem.isotropy_weight),
        worst_pitch_deg=metrics.worst_pitch_deg,
        worst_roll_deg=metrics.worst_roll_deg,
        worst_case_deg=total,
        values=dict(result.evaluation.values),
    )


def drift_front(
    problem,
    fractions=DEFAULT_DRIFT_FRACTIONS,
    *,
    seed=0,
    budget=None,
    progress=None,
    reference=None,
):
    """Trace white-noise resolution against drift sensitivity by the ε-constraint method.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
        The settings; every level optimises the white-noise objective under them, without
        its ``conditions``, whose worst-case total error each design gets instead.
    fractions : sequence of float, optional
        Drift limits as fractions of the white-noise optimum's drift, each in (0, 1).
    seed : int, optional
        Seed of every search.
    budget : reflector_opt.optimiser._search.SearchBudget, optional
    progress : callable, optional
        ``progress(fraction, message)``.
    reference : reflector_opt.optimiser._result.OptimisationResult, optional
        The design optimised in the problem's conditions, recorded beside the front.

    Returns
    -------
    DriftFront
        Raises :class:`~reflector_opt.util._errors.InputError` if no design meets the
        constraints at all (the white-noise optimum's search fails).
    """
    levels = sorted((float(f) for f in fractions), reverse=True)
    if not levels or not all(0.0 < f < 1.0 for f in levels):
        raise InputError(f"drift_fractions: each must lie strictly between 0 and 1, got {levels}")
    plain = dataclasses.replace(problem, conditions=None, drift_limit_deg=None)
    share = 1 / (len(levels) + 1)
    run = {"seed": seed, "budget": budget, "figures": functools.partial(_figures, problem)}
    (optimum,) = optimise_variants(
        [("white-noise optimum", None)],
        lambda _: plain,
        progress=scaled(progress, 0.0, share),
        **run,
    )
    if optimum.error is not None:
        raise optimum.error
    ref = None if reference is None else front_point(reference, None, problem)
    known = [optimum.figures["point"]] + ([] if ref is None else [ref])

    def least_drift(done):  # the warm start of a level: the design of least drift known
        found = [v.figures["point"] for v in done if v.error is None]
        return min(known + found, key=lambda p: p.drift_deg).values

    found = optimise_variants(
        [(f"drift ≤ {f * known[0].drift_deg:.3g}°", f * known[0].drift_deg) for f in levels],
        lambda limit: dataclasses.replace(plain, drift_limit_deg=limit),
        initial=least_drift,
        progress=scaled(progress, share, 1.0),
        **run,
    )
    points = [known[0]] + [
        v.figures["point"] if v.error is None else DriftPoint(v.value, False, reason=v.reason)
        for v in found
    ]
    table = None if problem.conditions is None else problem.conditions.to_dict()
    return DriftFront(tuple(_mark_dominated(_best_known(points, ref))), seed, table, ref)


def _figures(problem, result, level):
    """The front's record of a level's optimisation (``level``: its problem)."""
    return {"point": front_point(result, level.drift_limit_deg, problem)}


def _best_known(points, reference):
    """Each level with the best verified design that meets its limit, whichever run found it
    (``points``: the white-noise optimum, then the levels; ``reference``: the design optimised
    in the conditions, or None)."""
    known = [(p.label, p) for p in points if p.feasible]
    known += [] if reference is None else [("optimised in the conditions", reference)]
    out = [points[0]]
    for p in points[1:]:
        better = [
            (name, q)
            for name, q in known
            if q.drift_deg <= p.drift_limit_deg
            and not (p.feasible and q.objective_deg >= p.objective_deg)
        ]
        name, best = min(better, key=lambda item: item[1].objective_deg, default=(None, p))
        kept = {"drift_limit_deg": p.drift_limit_deg, "reason": p.reason, "kept_from": name}
        out.append(p if name is None else dataclasses.replace(best, **kept))
    return out


def _mark_dominated(points):
    """The points, each feasible one marked if another is no worse on both axes and better
    on one (drift and white-noise objective)."""
    feasible = [p for p in points if p.feasible]

    def beaten(p):
        return any(
            q.drift_deg <= p.drift_deg
            and q.objective_deg <= p.objective_deg
            and (q.drift_deg < p.drift_deg or q.objective_deg < p.objective_deg)
            for q in feasible
        )

    return [dataclasses.replace(p, dominated=beaten(p)) if p.feasible else p for p in points]


def _describe(p):
    if not p.feasible:
        return f"infeasible: {p.reason}"
    text = f"drift {fmt(p.drift_deg, unit='°')}, objective {fmt(p.objective_deg, unit='°')}"
    if math.isfinite(p.worst_case_deg):
        text += f", total in the conditions {fmt(p.worst_case_deg, unit='°')}"
    if p.kept_from is not None:
        text += f", the design of {p.kept_from}"
    return text + (" (dominated)" if p.dominated else "")
