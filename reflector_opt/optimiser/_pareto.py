"""Pareto front of angular resolution against distance-window margin.

A larger margin between the distance window and the sensor's usable range makes the design
robust to manufacturing error (a reflector printed a little large or small, a sensor seated
a little deep) but leaves a narrower window for the signal, so a worse resolution. The front
is traced by the ε-constraint method: the optimiser is rerun with the required margin at
each level, from the largest down, warm-started from the design of the level above.

In operating conditions (``problem.conditions``, the optimiser's default objective) each
level's search minimises its in-use worst-case error and the point records it,
``worst_case_deg`` (:attr:`ErrorBudget.worst_case_deg
<reflector_opt.analysis._budget.ErrorBudget.worst_case_deg>`), beside its white-noise floor
(the worst 1σ resolution); without conditions it is NaN.
"""

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from reflector_opt.optimiser._studies import Variant, optimise_variants
from reflector_opt.util._display import Summarised, fmt, more_rows
from reflector_opt.util._fileio import json_record

#: Default margin levels, mm.
DEFAULT_MARGINS_MM = (0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3)


@dataclass(frozen=True)
class ParetoPoint:
    """One level of the front.

    Attributes
    ----------
    required_margin_mm : float
        The margin the optimiser had to meet, mm.
    feasible : bool
        False if no design meets it (the other fields are then None or NaN).
    margin_mm : float
        The margin the design achieves, mm (≥ the required one).
    worst_pitch_deg, worst_roll_deg : float
        Worst-case 1σ resolution, degrees, on the workspace grid: the white-noise floor.
    objective_deg : float
    values : dict or None
        The design variables.
    reason : str or None
        Why the level is infeasible.
    worst_case_deg : float
        The in-use worst-case total error in the problem's conditions, degrees (NaN without
        conditions).
    yield_fraction : float
        Fraction of sampled built units meeting the targets (NaN until
        :func:`reflector_opt.optimiser._robust.front_yield` estimates it).
    yield_low, yield_high : float
        Its 95 % Wilson interval.
    yield_samples : int or None
        Units sampled.
    """

    required_margin_mm: float
    feasible: bool
    margin_mm: float = math.nan
    worst_pitch_deg: float = math.nan
    worst_roll_deg: float = math.nan
    objective_deg: float = math.nan
    values: dict | None = None
    reason: str | None = None
    worst_case_deg: float = math.nan
    yield_fraction: float = math.nan
    yield_low: float = math.nan
    yield_high: float = math.nan
    yield_samples: int | None = None

    @property
    def worst_deg(self):
        """The larger of the pitch and roll worst cases, degrees."""
        return max(self.worst_pitch_deg, self.worst_roll_deg)

    def to_dict(self):
        """JSON-ready record (NaN as null)."""
        return json_record(self)


@dataclass(frozen=True, repr=False)
class ParetoFront(Summarised):
    """Points of the front, in increasing required margin.

    Attributes
    ----------
    points : tuple of ParetoPoint
    seed : int
    yield_basis : dict or None
        What the points' yields count (targets, tolerances, samples, seed), once estimated.
    """

    points: tuple
    seed: int
    yield_basis: dict | None = None

    def _summary(self):
        """Title and (label, value) rows of :class:`ParetoFront`."""
        rows = [
            (f"margin ≥ {fmt(p.required_margin_mm, unit='mm')}", _level(p))
            for p in self.points[:SHOWN_LEVELS]
        ]
        rows += more_rows(len(self.points), SHOWN_LEVELS, "levels")
        title = (
            f"ParetoFront: {len(self.points)} levels, {len(self.feasible_points)} feasible, "
            f"seed {self.seed}"
        )
        return title, rows

    @property
    def feasible_points(self):
        """The levels for which a design exists."""
        return tuple(p for p in self.points if p.feasible)

    def to_dict(self):
        """JSON-ready document."""
        return {
            "format": "reflector-opt/pareto@1",
            "x": "distance-window margin, mm",
            "y": "worst-case 1σ resolution, degrees",
            "in_use": "worst_case_deg: the in-use worst-case total error in the conditions, "
            "degrees (null without conditions)",
            "seed": self.seed,
            "yield": self.yield_basis,
            "points": [p.to_dict() for p in self.points],
        }


def pareto_front(problem, margins_mm=DEFAULT_MARGINS_MM, *, seed=0, budget=None, progress=None):
    """Trace resolution against distance-window margin by the ε-constraint method.

    Parameters
    ----------
    problem : reflector_opt.optimiser.Problem
        Its ``distance_margin_mm`` is replaced by each level in turn.
    margins_mm : sequence of float, optional
        Required margins, mm.
    seed : int, optional
        Seed of every search.
    budget : SearchBudget, optional
    progress : callable, optional
        ``progress(fraction, message)``.

    Returns
    -------
    ParetoFront
        Points in increasing margin; plot it with
        :func:`reflector_opt.report.figures._optimiser.pareto_figure`. The levels are optimised
        from the largest margin down, each warm-started from the design of the level above:
        that design also meets the smaller margin, and the search never loses its best
        member. The verification's repair may still end a
        level worse than the level above (it overshoots a printed wall's shortfall); the
        level then keeps the design above, which meets its smaller margin too and is
        verified, so the resolution never worsens as the margin shrinks. A level that no
        design meets is recorded as infeasible, with the reason.
    """
    levels = sorted((float(m) for m in margins_mm), reverse=True)
    found = optimise_variants(
        [(f"margin {m:g} mm", m) for m in levels],
        lambda margin: dataclasses.replace(problem, distance_margin_mm=margin),
        initial=lambda done: _best(done).values,
        seed=seed,
        budget=budget,
        progress=progress,
    )
    points = [
        _point(v.value, _best(found[: i + 1]).result)
        if v.error is None
        else ParetoPoint(v.value, False, reason=v.reason)
        for i, v in enumerate(found)
    ]
    return ParetoFront(tuple(reversed(points)), seed)


def _best(variants):
    """The feasible variant of the lowest objective, the latest of equals (one without a
    design when none is feasible)."""
    feasible = [v for v in reversed(variants) if v.error is None]
    return min(feasible, key=lambda v: v.result.objective, default=Variant("", None))


def _point(margin, result):
    """The feasible level of required margin ``margin`` (mm) from its optimisation."""
    m, budget = result.metrics, getattr(result.evaluation, "budget", None)
    return ParetoPoint(
        required_margin_mm=margin,
        feasible=True,
        margin_mm=float(np.min(m.distance_margin_mm)),
        worst_pitch_deg=m.worst_pitch_deg,
        worst_roll_deg=m.worst_roll_deg,
        objective_deg=result.objective,
        values=dict(result.evaluation.values),
        worst_case_deg=math.nan if budget is None else float(budget.worst_case_deg),
    )


#: Levels a display lists; the rest are counted.
SHOWN_LEVELS = 15


def _level(p):
    """One level of the front as a display value."""
    if not p.feasible:
        return f"infeasible: {p.reason}"
    text = (
        f"worst {fmt(p.worst_deg, unit='°')}, margin {fmt(p.margin_mm, unit='mm')}, "
        f"objective {fmt(p.objective_deg, unit='°')}"
    )
    if math.isfinite(p.worst_case_deg):
        text += f", in-use worst case {fmt(p.worst_case_deg, unit='°')}"
    if math.isfinite(p.yield_fraction):
        text += f", yield {fmt(p.yield_fraction)} ({fmt(p.yield_low)} to {fmt(p.yield_high)})"
    return text
