"""What the optimiser found, and the ``predicted`` block of ``design.json`` it writes."""

import math
from dataclasses import dataclass, field

from msgspec import UNSET

from reflector_opt.util._display import Summarised, fmt, vector
from reflector_opt.util._fileio import json_number


@dataclass(frozen=True, repr=False)
class OptimisationResult(Summarised):
    """What :func:`~reflector_opt.optimiser._search.optimise` found.

    Attributes
    ----------
    design : reflector_opt.design._design.Design
        The optimised design on the workspace grid, with ``predicted`` filled in.
    evaluation : reflector_opt.optimiser._evaluation.Evaluation
        Its metrics and constraints on the workspace grid (0.1°).
    baseline : reflector_opt.optimiser._evaluation.Evaluation or None
        The built-in default geometry under the same part, envelope and noise (None if that
        geometry is not valid here).
    seed : int
    history : list of dict
        Per generation: ``generation``, ``best`` (penalised objective on the search grid) and
        ``spread`` (std/mean of the population's objectives; None while some are infeasible).
    evaluations : dict
        Objective (forward-model) evaluations per stage: ``search``, ``polish``, ``verify``
        and ``baseline`` (each on that stage's pose grid).
    seconds : dict
        Wall time per stage.
    budget : reflector_opt.optimiser._search.SearchBudget
    tightening : dict
        Extra constraint margins the repair needed (empty if none).
    read_out : reflector_opt.optimiser._readout.ReadOutChoice or None
        The read-out chosen for the design in use, and the default design's budget in the
        conditions as stated (None: the conditions' read-out was kept).
    """

    design: object
    evaluation: object
    baseline: object
    seed: int
    history: list
    evaluations: dict
    seconds: dict
    budget: object
    tightening: dict = field(default_factory=dict)
    read_out: object = None

    @property
    def objective(self):
        """Objective on the workspace grid, degrees."""
        return self.evaluation.objective

    @property
    def metrics(self):
        """:class:`~reflector_opt.analysis._metrics.DesignMetrics` on the workspace grid."""
        return self.evaluation.metrics

    @property
    def improvement(self):
        """The default design's figures over the optimised design's, or None.

        In use (the design judged in conditions): the worst case and the median of the total
        error (``worst``, ``median``, and ``pitch``, ``roll`` of the worst case), against the
        default design in the conditions as stated, with the white-noise ratios under
        ``resolution``; else the worst-case 1σ resolution's (pitch, roll, overall).
        """
        if self.baseline is None or self.baseline.metrics is None:
            return None
        base, opt = self.baseline.metrics, self.metrics
        resolution = {
            "pitch": _ratio(base.worst_pitch_deg, opt.worst_pitch_deg),
            "roll": _ratio(base.worst_roll_deg, opt.worst_roll_deg),
            "worst": _ratio(base.worst_resolution_deg, opt.worst_resolution_deg),
        }
        budget, base_budget = self.evaluation.budget, self._baseline_budget()
        if budget is None or base_budget is None:
            return resolution
        from reflector_opt.optimiser._conditions import median_total_deg, worst_totals

        (pitch, roll), (base_pitch, base_roll) = worst_totals(budget), worst_totals(base_budget)
        return {
            "basis": "in use",
            "worst": _ratio(base_budget.worst_case_deg, budget.worst_case_deg),
            "median": _ratio(median_total_deg(base_budget), median_total_deg(budget)),
            "pitch": _ratio(base_pitch, pitch),
            "roll": _ratio(base_roll, roll),
            "resolution": resolution,
        }

    def _baseline_budget(self):
        """The default design's budget the improvement in use is measured against: in the
        conditions as stated where the read-out was chosen, else the search's."""
        if self.read_out is not None:
            return self.read_out.baseline
        return None if self.baseline is None else self.baseline.budget

    # -- display (equality is the dataclass's, field by field) --

    def _summary(self):
        """Title and (label, value) rows of the key figures, units included."""
        ev = self.evaluation
        state = "feasible" if ev.feasible else f"infeasible: {ev.describe_failure()}"
        title = f"OptimisationResult: objective {fmt(self.objective, 4, '°')} ({state})"
        rows = []
        design = self.design if self.design is not None else ev.design
        if design is not None:
            r = design.reflector
            rows.append(
                (
                    "design",
                    f"{len(design.sensors)} sensors, sphere radius {r.radius_mm:.3f} mm at "
                    f"{vector(r.centre_mm, unit='mm')}",
                )
            )
        m = self.metrics
        if m is not None:
            rows += [
                (
                    "worst resolution",
                    f"pitch {fmt(m.worst_pitch_deg, 4, '°')}, roll "
                    f"{fmt(m.worst_roll_deg, 4, '°')} (on the {fmt(m.step_deg, unit='°')} grid)",
                ),
                (
                    "distance margin",
                    f"{fmt(float(min(m.distance_margin_mm)), unit='mm')} "
                    "(smallest over the sensors)",
                ),
            ]
        if ev.budget is not None:
            rows.append(("in the conditions", _conditions_row(self)))
        if ev.constraints:
            tightest = min(ev.constraints, key=lambda c: c.margin / c.scale)
            met = sum(c.met for c in ev.constraints)
            rows.append(
                (
                    "constraints",
                    f"{met} of {len(ev.constraints)} met; tightest {tightest.name} "
                    f"(margin {fmt(tightest.margin, unit=tightest.unit)})",
                )
            )
        if self.baseline is None or self.baseline.metrics is None:
            rows.append(("baseline", "none (the default geometry is not valid here)"))
        else:
            gain = self.improvement
            what = "worst case in use" if "basis" in gain else "worst resolution"
            rows.append(
                (
                    "baseline",
                    f"objective {fmt(self.baseline.objective, 4, '°')}; {what} improved "
                    f"{fmt(gain['worst'])}×",
                )
            )
        if ev.values:
            rows.append(("variables", ", ".join(f"{k} {fmt(v, 4)}" for k, v in ev.values.items())))
        total = sum(self.evaluations.values())
        rows.append(
            (
                "search",
                f"seed {self.seed}, {len(self.history)} generation"
                f"{'' if len(self.history) == 1 else 's'}, {total} evaluations, "
                f"{fmt(sum(self.seconds.values()), unit='s')}",
            )
        )
        if self.tightening:
            rows.append(
                (
                    "repair tightening",
                    ", ".join(f"{k} {fmt(v)}" for k, v in self.tightening.items()),
                )
            )
        return title, rows

    def predicted(self):
        """The ``predicted`` block of ``design.json``: metrics, margins, search record."""
        out = {
            "objective_deg": self.objective,
            "metrics": self.metrics.to_dict(),
            "constraints": self.evaluation.constraints_dict(),
            "optimiser": {
                "seed": self.seed,
                "evaluations": dict(self.evaluations),
                "generations": len(self.history),
                "seconds": {k: round(v, 3) for k, v in self.seconds.items()},
                "budget": self.budget.__dict__.copy(),
                "variables": dict(self.evaluation.values),
                "repair_tightening": dict(self.tightening),
            },
        }
        if self.baseline is not None and self.baseline.metrics is not None:
            out["baseline"] = {
                "design": "built-in default geometry, same part, envelope and noise",
                "objective_deg": json_number(self.baseline.objective),
                "metrics": self.baseline.metrics.to_dict(),
                "feasible": self.baseline.feasible,
            }
            out["improvement"] = self.improvement
        if self.evaluation.budget is not None:
            out["conditions"] = conditions_block(self)
        return out


def conditions_block(result):
    """``predicted.conditions``: the conditions, the design's budget in them, the sources
    that bind, its drift sensitivity, and the default design's budget in the same conditions.

    Parameters
    ----------
    result : OptimisationResult
        Optimised in operating conditions (its evaluation holds the budget).

    Returns
    -------
    reflector_opt.design._in_use.InUse
    """
    from reflector_opt.analysis._budget import drift_sensitivity
    from reflector_opt.design._in_use import InUse, InUseBaseline
    from reflector_opt.optimiser._conditions import (
        binding_sources,
        budget_step_deg,
        median_total_deg,
        rms_total_deg,
        worst_totals,
    )

    budget = result.evaluation.budget
    pitch, roll = worst_totals(budget)
    drift = drift_sensitivity(result.evaluation.design)
    base, same = result._baseline_budget(), result.baseline
    baseline = UNSET
    if base is not None:
        baseline = InUseBaseline(
            conditions="as stated" if result.read_out is not None else "the same",
            worst_case_deg=base.worst_case_deg,
            rms_deg=rms_total_deg(base),
            median_deg=median_total_deg(base),
            budget=base.to_dict(),
            binding=binding_sources(base),
        )
    median = median_total_deg(budget)
    same_read_out = UNSET
    if result.read_out is not None and same is not None and same.budget is not None:
        same_read_out = {
            "worst_case_deg": same.budget.worst_case_deg,
            "median_deg": median_total_deg(same.budget),
        }
    return InUse(
        conditions=budget.conditions.to_dict(),
        objective="worst-case total error in the conditions (largest over poses and angles "
        "of the root-sum-square of every source's worst-scenario error, noise at 1σ), with the "
        "isotropy factor; the calibration form's misfit left out",
        grid_deg={
            "search": budget_step_deg(result.budget.grid_step_deg),
            "polish": budget_step_deg(result.budget.polish_step_deg),
            "verified": budget_step_deg(result.metrics.step_deg),
        },
        worst_case_deg=budget.worst_case_deg,
        worst_pitch_deg=pitch,
        worst_roll_deg=roll,
        rms_deg=rms_total_deg(budget),
        median_deg=median,
        white_noise_floor_deg=result.metrics.worst_resolution_deg,
        budget=budget.to_dict(),
        binding=binding_sources(budget),
        drive=budget.drive.to_dict(),
        joint=budget.joint.to_dict(),
        assumed_figures=list(budget.assumed),
        drift_sensitivity={name: e.to_dict() for name, e in drift.items()},
        read_out=UNSET if result.read_out is None else result.read_out.to_dict(),
        baseline=baseline,
        improvement=UNSET if base is None else _ratio(base.worst_case_deg, budget.worst_case_deg),
        improvement_median=UNSET if base is None else _ratio(baseline.median_deg, median),
        baseline_read_out=same_read_out,
    )


def _conditions_row(result):
    """The worst-case total error in the conditions, against the default design's."""
    text = f"worst-case total error {fmt(result.evaluation.budget.worst_case_deg, 4, '°')}"
    base = result._baseline_budget()
    if base is not None:
        text += f" (default design {fmt(base.worst_case_deg, 4, '°')})"
    return text


def _ratio(a, b):
    if not (math.isfinite(a) and math.isfinite(b)) or b <= 0:
        return None
    return a / b
