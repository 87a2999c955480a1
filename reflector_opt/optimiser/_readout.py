"""The read-out a design is used with, chosen for it: drive scheme, sample rate, calibration.

A unit in use is its geometry together with how it is read: the LEDs' drive (``dc``, one at a
time ``multiplexed``, or ``modulated`` and differenced), the ADC's sample rate, and whether the
calibration is temperature-compensated (a thermometer on the strip and data at several
temperatures; docs/conditions.md). Each changes what the error budget
(:func:`~reflector_opt.analysis._budget.error_budget`) leaves: a switched drive removes the
neighbours' light and, differenced, the ambient light and the supply's step at the collector,
but below the detectors' settling rate only; compensation takes out the temperature's first
order and leaves the thermometer's error.

:func:`choose_read_out` judges every candidate of :func:`read_out_candidates` by its
worst-case total error in use on the budget's 1° grid and keeps the simplest within
:data:`READ_OUT_WORTH` of the best: a thermometer, a switched drive or a lower frame rate is
taken only where it buys at least that much. The candidates, in order of what they cost:

1. ``dc`` at the stated sample rate, uncompensated (the conditions' default);
2. ``multiplexed`` and then ``modulated`` at the stated rate, or at the detectors' settling
   rate (:func:`~reflector_opt.model._settling.settling_rate_hz`) where that is lower;
3. each of those compensated.
"""

import dataclasses
import math
from dataclasses import dataclass

from reflector_opt.analysis._budget import BUDGET_STEP_DEG, error_budget
from reflector_opt.model._drive import DRIVES
from reflector_opt.optimiser._conditions import median_total_deg

#: The share of the worst case a costlier read-out must buy to be chosen over a simpler one.
READ_OUT_WORTH = 0.05

#: The keys of a conditions table a read-out sets.
READ_OUT_KEYS = ("drive", "sample_rate_hz", "temperature_compensated")


@dataclass(frozen=True)
class ReadOut:
    """One read-out of a design and what it leaves in use.

    Attributes
    ----------
    conditions : reflector_opt.design._conditions.Conditions
        The conditions with the read-out's drive, sample rate and compensation.
    worst_case_deg, median_deg : float
        The worst-case and median total error in them, degrees (the budget's 1° grid).
    frame_rate_hz : float
        Complete readings of a unit per second.
    """

    conditions: object
    worst_case_deg: float
    median_deg: float
    frame_rate_hz: float

    def to_dict(self):
        """The read-out as plain values (design.json's ``read_out`` rows)."""
        return {
            **{key: getattr(self.conditions, key) for key in READ_OUT_KEYS},
            "worst_case_deg": self.worst_case_deg,
            "median_deg": self.median_deg,
            "frame_rate_hz": self.frame_rate_hz,
        }


def _judged(design, conditions, step_deg):
    budget = error_budget(design, conditions, step_deg=step_deg)
    return budget, ReadOut(
        conditions, budget.worst_case_deg, median_total_deg(budget), budget.drive.frame_rate_hz
    )


def read_out_candidates(design, conditions, step_deg=BUDGET_STEP_DEG):
    """Every read-out :func:`choose_read_out` weighs, judged, cheapest first (module notes).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    conditions : reflector_opt.design._conditions.Conditions
        The stated conditions: their sample rate, and everything but the read-out.
    step_deg : float, optional
        The budget's grid, degrees.

    Returns
    -------
    list of ReadOut
    """
    stated = conditions.replace(drive="dc", temperature_compensated=False)
    budget, first = _judged(design, stated, step_deg)
    rate, settling = conditions.sample_rate_hz, budget.drive.settling_rate_hz
    if settling is not None and settling < rate:
        rate = _round_down(settling)
    plain = [first] + [
        _judged(design, stated.replace(drive=drive, sample_rate_hz=rate), step_deg)[1]
        for drive in DRIVES[1:]
    ]
    compensated = [
        _judged(design, r.conditions.replace(temperature_compensated=True), step_deg)[1]
        for r in plain
    ]
    return plain + compensated


def _round_down(rate_hz):
    """A rate to two significant figures, rounded down (an ADC's setting), Hz."""
    scale = 10.0 ** (math.floor(math.log10(rate_hz)) - 1)
    return math.floor(rate_hz / scale) * scale


def choose_read_out(design, conditions, step_deg=BUDGET_STEP_DEG):
    """The simplest read-out within :data:`READ_OUT_WORTH` of the best one in use.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    conditions : reflector_opt.design._conditions.Conditions
        The stated conditions.
    step_deg : float, optional
        The budget's grid, degrees.

    Returns
    -------
    (ReadOut, list of ReadOut)
        The chosen read-out and every candidate judged, cheapest first.
    """
    candidates = read_out_candidates(design, conditions, step_deg)
    best = min(r.worst_case_deg for r in candidates)
    chosen = next(r for r in candidates if r.worst_case_deg <= best * (1.0 + READ_OUT_WORTH))
    return chosen, candidates


@dataclass(frozen=True)
class ReadOutChoice:
    """The read-out chosen for an optimised design, and what the default design meets as stated.

    Attributes
    ----------
    chosen : ReadOut
    candidates : list of ReadOut
        Every read-out judged, cheapest first.
    stated : reflector_opt.design._conditions.Conditions
        The conditions as stated (their read-out the default design's).
    baseline : reflector_opt.analysis._budget.ErrorBudget or None
        The default design's budget in ``stated``: what the improvement is measured against.
    searched_in : reflector_opt.design._conditions.Conditions or None
        The conditions the geometry was searched in.
    missed : str or None
        Why the search in the read-out chosen for the default design gave no design (the
        geometry then searched as stated), or None.
    default : ReadOut or None
        The read-out chosen for the default design, with what that design meets in it.
    """

    chosen: ReadOut
    candidates: list
    stated: object
    baseline: object = None
    searched_in: object = None
    missed: str | None = None
    default: ReadOut | None = None

    def to_dict(self):
        """design.json's ``predicted.conditions.read_out``."""
        return {
            "chosen": self.chosen.to_dict(),
            "stated": {key: getattr(self.stated, key) for key in READ_OUT_KEYS},
            "searched_in": None
            if self.searched_in is None
            else {key: getattr(self.searched_in, key) for key in READ_OUT_KEYS},
            "missed": self.missed,
            "default_design": None if self.default is None else self.default.to_dict(),
            "worth": READ_OUT_WORTH,
            "candidates": [r.to_dict() for r in self.candidates],
        }


def judged_in(result, problem, *, in_use=True):
    """An optimisation's design and its default design judged again in ``problem.conditions``.

    Parameters
    ----------
    result : reflector_opt.optimiser._result.OptimisationResult
    problem : reflector_opt.optimiser._problem.Problem
        The problem with the conditions to judge in (a chosen read-out, or the conditions a
        white-noise search is reported in).
    in_use : bool, optional
        True: the objective becomes the in-use one; False keeps the white-noise objective.

    Returns
    -------
    reflector_opt.optimiser._result.OptimisationResult
        With the evaluations' budgets and ``design.predicted`` made again (its other keys kept).
    """
    evaluation, baseline = (
        rejudged(e, problem, in_use=in_use) for e in (result.evaluation, result.baseline)
    )
    result = dataclasses.replace(result, evaluation=evaluation, baseline=baseline)
    return with_predicted(result)


def with_predicted(result):
    """``result`` with its design's ``predicted`` made again (its other keys kept)."""
    predicted = result.design.predicted.replace(**result.predicted())
    return dataclasses.replace(result, design=result.evaluation.design.replace(predicted=predicted))


def rejudged(evaluation, problem, *, in_use=True):
    """An evaluation on its workspace grid with its budget in ``problem.conditions`` (None
    stays None); ``in_use`` False keeps its objective."""
    from reflector_opt.optimiser._evaluation import in_conditions

    if evaluation is None:
        return None
    fresh = dataclasses.replace(evaluation, budget=None)
    judged = in_conditions(problem, fresh, None, design=evaluation.design)
    return judged if in_use else dataclasses.replace(judged, objective=evaluation.objective)


def with_read_out(result, problem, stated, missed=None, default=None):
    """An in-use optimisation with the read-out chosen for its design (module notes).

    Parameters
    ----------
    result : reflector_opt.optimiser._result.OptimisationResult
        Searched under ``problem`` (its conditions: the read-out chosen for the default
        design, or the stated one).
    problem : reflector_opt.optimiser._problem.Problem
    stated : reflector_opt.design._conditions.Conditions
        The conditions as stated.
    missed : str, optional
        Why the search in the read-out chosen for the default design gave no design, where
        ``problem``'s is the stated one for that reason.
    default : ReadOut, optional
        The read-out chosen for the default design.

    Returns
    -------
    reflector_opt.optimiser._result.OptimisationResult
        Judged in the read-out that suits its own design best, with :class:`ReadOutChoice`.
    """
    chosen, candidates = choose_read_out(result.evaluation.design, stated)
    if chosen.conditions != problem.conditions:
        result = judged_in(result, dataclasses.replace(problem, conditions=chosen.conditions))
    base = rejudged(result.baseline, dataclasses.replace(problem, conditions=stated))
    budget = None if base is None else base.budget
    choice = ReadOutChoice(chosen, candidates, stated, budget, problem.conditions, missed, default)
    return with_predicted(dataclasses.replace(result, read_out=choice))
