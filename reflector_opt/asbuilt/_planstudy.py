"""A calibration plan for identification: the D-optimal plan, its size, what backs it.

A calibration plan for a polynomial must cover the workspace evenly; a plan for the as-built
identification (:func:`reflector_opt.asbuilt._identification.identify`) need only hold the
poses whose voltages tell the most about a unit's as-built parameters.
:func:`plan_identification` does it all for ``reflector-opt plan-calibration --for
identification``:

* the candidate poses and their information (:mod:`reflector_opt.asbuilt._poses`);
* the D-optimal plan and the poses it needs to bring every determinable parameter's
  posterior std below the target (:mod:`reflector_opt.asbuilt._doe`);
* D-optimal against the Sobol and grid patterns of the same sizes
  (:mod:`reflector_opt.asbuilt._patterns`);
* the prediction checked by identifying simulated units on each plan
  (:mod:`reflector_opt.asbuilt._plancheck`), and the calibration forms predicted on the same
  units (:func:`reflector_opt.tolerance._planning.predict_plans`);

its result an :class:`IdentificationStudy`.
"""

from dataclasses import dataclass

import numpy as np

from reflector_opt.asbuilt._doe import PoseCount, minimum_poses, poses_needed
from reflector_opt.asbuilt._patterns import (
    PATTERNS,
    SIZES,
    PatternRow,
    compare_patterns,
    pattern_row,
)
from reflector_opt.asbuilt._plancheck import check_plans
from reflector_opt.asbuilt._poses import (
    CANDIDATE_STEP_DEG,
    PoseInformation,
    candidate_poses,
    pose_information,
)
from reflector_opt.asbuilt._uncertainty import DETERMINED_RATIO
from reflector_opt.tolerance._planning import predict_plans
from reflector_opt.util._display import Summarised, fmt
from reflector_opt.util._errors import InputError


@dataclass(frozen=True, repr=False)
class IdentificationStudy(Summarised):
    """A plan for identification and what backs it.

    Attributes
    ----------
    info : reflector_opt.asbuilt._poses.PoseInformation
        The candidate poses and their sensitivity blocks.
    count : reflector_opt.asbuilt._doe.PoseCount
        The poses the D-optimal plan needs to reach the target.
    plan : reflector_opt.asbuilt._patterns.PatternRow or None
        The chosen D-optimal plan (``count.n_poses`` poses, visiting order); None when no
        parameter reaches the target.
    rows : list of reflector_opt.asbuilt._patterns.PatternRow
        Every pattern and size compared.
    checks : list of reflector_opt.asbuilt._plancheck.CheckRow
        The identifications of simulated units on each compared plan, then on the chosen
        one (pattern ``chosen``); empty when not checked.
    comparison : reflector_opt.tolerance._planning.PlanStudy or None
        The calibration forms on the same units, plans and noise draws.
    n_units, seed : int
    truth : str
        ``built`` or ``model`` (:func:`~reflector_opt.asbuilt._plancheck.check_plans`).
    candidate_step_deg : float
        Step of the candidate grid, degrees.
    """

    info: PoseInformation
    count: PoseCount
    plan: PatternRow
    rows: list
    checks: list
    comparison: object
    n_units: int
    seed: int
    truth: str
    candidate_step_deg: float

    def _summary(self):
        """Title and (label, value) rows of :class:`IdentificationStudy`."""
        plan = self.plan
        rows = [
            ("target std ratio", fmt(self.count.target)),
            ("poses needed", str(self.count.n_poses)),
            (
                "chosen plan",
                "none reaches the target"
                if plan is None
                else f"{plan.pattern}, {plan.n_poses} poses, log det M {fmt(plan.log_det)}",
            ),
            ("plans compared", str(len(self.rows))),
            ("plans checked", str(len(self.checks))),
            (
                "calibration forms compared",
                "no"
                if self.comparison is None
                else f"{len(self.comparison.predictions)} predictions",
            ),
            ("candidate grid step", fmt(self.candidate_step_deg, unit="°")),
        ]
        title = f"IdentificationStudy: {self.n_units} units ({self.truth} truth), seed {self.seed}"
        return title, rows

    def check(self, pattern, n_poses):
        """The CheckRow of a plan, or None."""
        return next((c for c in self.checks if (c.pattern, c.n_poses) == (pattern, n_poses)), None)

    def within_floor(self, within=0.10):
        """Smallest plan per method and pattern whose angle RMS is within a fraction of the floor.

        Parameters
        ----------
        within : float
            Allowed excess over the units' Cramér–Rao floor on both angles.

        Returns
        -------
        dict
            ``{"identification": {pattern: n or None}, form: {pattern: n or None}, …}``.
        """
        plans = [(row, self.check(row.pattern, row.n_poses)) for row in self.rows]
        found = [("identification", r, c.rms_deg, c.floor_deg) for r, c in plans if c is not None]
        if self.comparison is not None:
            floor = self.comparison.floor_rms_deg
            found += [(p.form, p, p.rms_deg, floor) for p in self.comparison.predictions]
        out = {"identification": {}}
        for method, plan, rms_deg, floor_deg in found:
            best = out.setdefault(method, {}).get(plan.pattern)
            if np.all(rms_deg <= (1.0 + within) * floor_deg):
                best = plan.n_poses if best is None else min(best, plan.n_poses)
            out[method][plan.pattern] = best
        return out

    def to_dict(self, within=0.10):
        """JSON-ready: settings, per-parameter figures, every plan and its check."""
        names, chosen = self.info.names, self.check("chosen", self.count.n_poses)
        parameters = _parameter_entries(self, chosen)
        patterns = []
        for row in self.rows:
            entry = row.to_dict(names, self.count.target)
            found = self.check(row.pattern, row.n_poses)
            entry["check"] = None if found is None else found.to_dict(names)
            patterns.append(entry)
        return {
            "for": "identification",
            "target_std_ratio": self.count.target,
            "candidates": {
                "step_deg": self.candidate_step_deg,
                "n_poses": len(self.info),
            },
            "reference_sigma_deg": float(self.info.settings["reference_sigma_deg"]),
            "n_units": self.n_units,
            "seed": self.seed,
            "truth": self.truth,
            "parameters": parameters,
            "recommended": None if self.plan is None else self._recommended(chosen),
            "patterns": patterns,
            "within": within,
            "smallest_within_floor": self.within_floor(within),
            "calibration": None if self.comparison is None else self.comparison.to_dict(),
        }

    def _recommended(self, chosen):
        out = self.plan.to_dict(self.info.names, self.count.target)
        out["determinable"] = list(self.count.determinable)
        out["check"] = None if chosen is None else chosen.to_dict(self.info.names)
        return out


def _parameter_entries(study, chosen):
    """Per parameter of an :class:`IdentificationStudy`: its prior, std ratios and the poses
    it needs (JSON-ready); ``chosen`` is the check of the chosen plan, or None."""
    entries = []
    for j, name in enumerate(study.info.names):
        entry = {
            "name": name,
            "prior_std": float(study.info.prior_std[j]),
            "ratio_all_candidates": float(study.count.ratio_all[j]),
            "poses_needed": study.count.needed[name],
        }
        if study.plan is not None:
            entry["plan_ratio"] = float(study.plan.ratio[j])
        if chosen is not None:
            entry["achieved_ratio"] = float(chosen.achieved[j])
        entries.append(entry)
    return entries


def _check_request(design, info, patterns, sizes, compare_forms, truth):
    """Refuse patterns, sizes and comparisons the identification planner cannot make."""
    if len(design.sensors) != 2:
        raise InputError("plan for identification: the design must have exactly two sensors")
    allowed = ("d-optimal", "sobol", "grid", "spiral")
    unknown = [p for p in patterns if p not in allowed]
    if unknown:
        raise InputError(
            f"patterns: {', '.join(unknown)} cannot be planned for identification; "
            f"known: {', '.join(allowed)}"
        )
    least = minimum_poses(info.rows)
    small = [n for n in sizes if n < least]
    if small:
        raise InputError(
            f"sizes: {small[0]} poses are too few to identify {len(info.names)} parameters "
            f"from {len(design.sensors)} sensors; give at least {least}"
        )
    if "d-optimal" in patterns and max(sizes, default=0) > len(info):
        raise InputError(
            f"sizes: {max(sizes)} poses exceed the {len(info)} candidates of the candidate "
            "grid; give a finer candidate step"
        )
    if compare_forms and truth != "built":
        raise InputError("calibration forms are compared on built units only (truth 'built')")


def _comparison(design, forms, patterns, sizes, n_units, seed, progress):
    """The calibration forms' predictions on the same units and plans (or None)."""
    if not forms or not n_units:
        return None
    if progress is not None:
        progress(f"calibration forms {', '.join(forms)} on the same units")
    return predict_plans(
        design,
        forms=tuple(forms),
        patterns=tuple(p for p in patterns if p != "d-optimal"),
        sizes=tuple(sizes),
        n_units=n_units,
        seed=seed,
    )


def plan_identification(
    design,
    *,
    sizes=SIZES,
    patterns=PATTERNS,
    target=DETERMINED_RATIO,
    n_units=3,
    seed=0,
    truth="built",
    compare_forms=(),
    candidate_step_deg=CANDIDATE_STEP_DEG,
    progress=None,
):
    """Plan a calibration for identification: the D-optimal plan, its size, its check.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        Two sensors.
    sizes : sequence of int
        Plan sizes to compare (poses).
    patterns : sequence of str
        Among ``d-optimal``, ``sobol``, ``grid``, ``spiral``.
    target : float
        Posterior over prior std each determinable parameter must reach, in (0, 1).
    n_units : int
        Simulated units each plan is checked on (0: no check).
    seed : int
        Seed of the units, the Sobol scrambling and every noise draw.
    truth : {"built", "model"}
        The simulated units (:func:`~reflector_opt.asbuilt._plancheck.check_plans`).
    compare_forms : sequence of str
        Calibration forms to predict on the same units and plans
        (:func:`reflector_opt.tolerance._planning.predict_plans`; needs built units).
    candidate_step_deg : float
        Step of the candidate grid, degrees.
    progress : callable, optional
        Called with a short text before each long step.

    Returns
    -------
    IdentificationStudy
    """
    info = pose_information(design, candidate_poses(design.workspace, candidate_step_deg))
    _check_request(design, info, patterns, sizes, compare_forms, truth)
    count = poses_needed(info.rows, info.names, target)
    plan = None
    if count.n_poses:
        plan = pattern_row("d-optimal", info.poses_deg[count.indices], info.rows[count.indices])
    rows = compare_patterns(info, sizes, patterns, seed)
    plans = [(r.pattern, r.poses_deg) for r in rows]
    plans += [] if plan is None else [("chosen", plan.poses_deg)]
    checks = []
    if n_units:
        checks = check_plans(
            design, plans, n_units=n_units, seed=seed, truth=truth, progress=progress
        )
    comparison = _comparison(design, compare_forms, patterns, sizes, n_units, seed, progress)
    settings = (int(n_units), int(seed), truth, float(candidate_step_deg))
    return IdentificationStudy(info, count, plan, rows, checks, comparison, *settings)
