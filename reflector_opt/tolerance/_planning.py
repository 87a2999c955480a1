"""Calibration planning: predicted error against the number and pattern of poses, per form.

For a design, :func:`predict_plans` draws a few built units
(:func:`reflector_opt.tolerance._builtunit.build_unit`), and for every plan pattern
(:data:`reflector_opt.calibration._plans.PATTERNS`), plan size and calibration form
(:data:`FORMS`) records each unit's calibration data on that plan, fits the form and
validates it on independent poses with the true angles: the RMS and maximum error pooled
over the units (RMS of the units' RMS, the largest maximum), beside the units' Cramér–Rao
floor. :func:`recommend` picks the smallest plan within a given fraction of the floor (10 %
by default) and :func:`motion_time_s` estimates how long the rig takes to visit it.
"""

from dataclasses import dataclass

import numpy as np

from reflector_opt.calibration._estimators import make_estimator, selected
from reflector_opt.calibration._physical import PhysicalModel
from reflector_opt.calibration._plans import PATTERNS, make_plan, path_length_deg
from reflector_opt.calibration._selection import AutoModel
from reflector_opt.tolerance._builtunit import (
    REFERENCE_SIGMA_DEG,
    build_unit,
    built_unit_protocol,
    crlb_floor_deg,
)
from reflector_opt.util._display import Summarised, fmt, more_rows
from reflector_opt.util._errors import InputError
from reflector_opt.util._pools import local_processes, run_batches
from reflector_opt.util._progress import no_progress
from reflector_opt.util._seeds import stream_rng

#: Calibration forms the planner compares: the paper's Eq 6, the form chosen by
#: cross-validation, and the physical model.
FORMS = ("eq6", "auto", "physical")

#: Plan sizes (poses) of the coarse patterns; the raster's size is set by the workspace step.
SIZES = (25, 50, 100, 200, 400, 1000, 4000, 16000)

#: Largest plan the physical form is fitted to (its fit grows with the poses; beyond this
#: size a polynomial has long reached the floor).
MAX_PHYSICAL_POSES = 200

#: Validation poses per unit.
N_VALIDATION = 2000


def _pitch_roll(values):
    """``{"pitch": …, "roll": …}`` of a pair of numbers, as floats."""
    return {"pitch": float(values[0]), "roll": float(values[1])}


@dataclass(frozen=True)
class PlanPrediction:
    """Predicted error of one form on one plan, pooled over the built units.

    Attributes
    ----------
    pattern : str
    n_poses : int
    form : str
    rms_deg, max_deg : numpy.ndarray
        Pitch and roll, degrees.
    models : tuple of str
        The model each unit ended with (the chosen form for ``auto``).
    path_deg : float
        Length of the plan's path, degrees.
    """

    pattern: str
    n_poses: int
    form: str
    rms_deg: np.ndarray
    max_deg: np.ndarray
    models: tuple
    path_deg: float

    def to_dict(self, floor_deg):
        """JSON-ready, with the ratio of the RMS to the floor (pitch, roll)."""
        return {
            "pattern": self.pattern,
            "n_poses": self.n_poses,
            "form": self.form,
            "rms_deg": _pitch_roll(self.rms_deg),
            "max_deg": _pitch_roll(self.max_deg),
            "floor_ratio": _pitch_roll(self.rms_deg / np.asarray(floor_deg)),
            "models": list(self.models),
            "path_deg": self.path_deg,
        }


@dataclass(frozen=True, repr=False)
class PlanStudy(Summarised):
    """Every prediction of a planning run and the units' Cramér–Rao floor.

    Attributes
    ----------
    predictions : list of PlanPrediction
    floor_rms_deg : numpy.ndarray
        The units' Cramér–Rao bound, RMS over the validation poses and the units (pitch,
        roll), degrees.
    n_units : int
    seed : int
    """

    predictions: list
    floor_rms_deg: np.ndarray
    n_units: int
    seed: int

    def _summary(self):
        """Title and (label, value) rows of :class:`PlanStudy`."""
        floor = self.floor_rms_deg
        rows = [
            (
                "Cramér–Rao floor RMS",
                f"pitch {fmt(floor[0], unit='°')}, roll {fmt(floor[1], unit='°')}",
            )
        ]
        for p in self.predictions[:SHOWN_PREDICTIONS]:
            rows.append(
                (
                    f"{p.pattern}, {p.n_poses} poses, {p.form}",
                    f"RMS {fmt(p.rms_deg[0], unit='°')} / {fmt(p.rms_deg[1], unit='°')} "
                    f"({fmt(p.rms_deg[0] / floor[0])} / {fmt(p.rms_deg[1] / floor[1])} × floor)",
                )
            )
        rows += more_rows(len(self.predictions), SHOWN_PREDICTIONS, "predictions")
        title = (
            f"PlanStudy: {len(self.predictions)} predictions on {self.n_units} units, "
            f"seed {self.seed}"
        )
        return title, rows

    def to_dict(self):
        """JSON-ready: the floor, the settings and every prediction."""
        return {
            "n_units": self.n_units,
            "seed": self.seed,
            "reference_sigma_deg": REFERENCE_SIGMA_DEG,
            "floor_rms_deg": _pitch_roll(self.floor_rms_deg),
            "predictions": [p.to_dict(self.floor_rms_deg) for p in self.predictions],
        }


def _units_and_floor(design, n_units, seed, n_validation, progress):
    """The built units and their Cramér–Rao floor (RMS over validation poses and units)."""
    units = []
    for i in range(int(n_units)):
        progress(0.1 * i / n_units, f"building unit {i + 1} of {n_units} (exact optics)")
        units.append(build_unit(design, i, seed=seed))
    reference = design.workspace.sample(stream_rng(seed, "reference_poses"), n_validation)
    floor = np.sqrt(np.mean([crlb_floor_deg(u, reference) ** 2 for u in units], axis=0))
    if not np.all(np.isfinite(floor)):  # plan.json would hold an infinite floor
        raise InputError(
            "the design's voltages do not determine the pose (the units' Cramér–Rao floor is "
            "infinite: no usable signal, e.g. a sensor far outside its range or a reflectance "
            "near zero); there is no calibration to plan"
        )
    return units, floor


def _plans(workspace, patterns, sizes, seed):
    """(pattern, poses) of every plan: the raster once, each other pattern at every size."""
    plans = []
    for pattern in patterns:
        if pattern == "raster":
            plans.append((pattern, make_plan(workspace, pattern)))
        else:
            plans += [(pattern, make_plan(workspace, pattern, n, seed=seed)) for n in sizes]
    return plans


def _fits(template, n_poses):
    """Whether a form is fitted to a plan of ``n_poses``: the physical form up to
    :data:`MAX_PHYSICAL_POSES`, a fixed polynomial with two poses per coefficient."""
    if isinstance(template, PhysicalModel):
        return n_poses <= MAX_PHYSICAL_POSES
    return isinstance(template, AutoModel) or n_poses >= 2 * len(template.terms)


def _predict(template, protocols, pattern, plan, form):
    """One form on one plan, fitted on each unit's data and validated: a PlanPrediction."""
    rms, peak, models = [], [], []
    for protocol in protocols:
        cal, val = protocol.calibration, protocol.validation
        fitted = template.clone().fit(cal.volts, cal.angles_deg)
        error = fitted.predict(val.volts) - val.angles_deg
        rms.append(np.sqrt(np.mean(error**2, axis=0)))
        peak.append(np.abs(error).max(axis=0))
        models.append(selected(fitted).name)
    return PlanPrediction(
        pattern=pattern,
        n_poses=len(plan),
        form=form,
        rms_deg=np.sqrt(np.mean(np.square(rms), axis=0)),
        max_deg=np.max(peak, axis=0),
        models=tuple(models),
        path_deg=path_length_deg(plan),
    )


def plan_predictions(context, batch):
    """Every form's prediction on one plan (the unit of work sent to a worker process).

    Parameters
    ----------
    context : tuple
        ``(units, templates, n_validation, seed)``: the built units, the forms' unfitted
        templates by name, the validation poses per unit and the seed of the noise draws.
    batch : tuple
        ``(pattern, plan)``: the plan's pattern and its poses, shape (n, 2), degrees.

    Returns
    -------
    list of PlanPrediction
        One per form fitted to a plan of this size, in the order of ``templates``.
    """
    from threadpoolctl import threadpool_limits

    units, templates, n_validation, seed = context
    pattern, plan = batch
    with threadpool_limits(limits=1):  # many small fits: threads gain nothing, contend much
        protocols = [
            built_unit_protocol(u, plan, n_validation=n_validation, seed=seed) for u in units
        ]
        return [
            _predict(template, protocols, pattern, plan, form)
            for form, template in templates.items()
            if _fits(template, len(plan))
        ]


def _cost(plan, templates):
    """Rough relative cost of a plan's fits, to hand the costliest to the workers first."""
    physical = any(isinstance(t, PhysicalModel) and _fits(t, len(plan)) for t in templates)
    return len(plan) + (20000 if physical else 0)


def predict_plans(
    design,
    *,
    forms=FORMS,
    patterns=PATTERNS,
    sizes=SIZES,
    n_units=3,
    seed=0,
    n_validation=N_VALIDATION,
    progress=None,
    factory=None,
):
    """Predict the calibration error of every form on every plan, against built units.

    The plans are shared among worker processes (``factory``), each plan's fits in one
    process with one BLAS thread: the many small least-squares problems gain nothing from
    more threads, and threads that contend for the cores make them several times slower
    (docs/performance-calibration.md). The results do not depend on the workers.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        Two sensors.
    forms : sequence of str
        Among :data:`FORMS` and any ``make_model`` name (``eq5``, ``polyN``).
    patterns : sequence of str
        Among :data:`~reflector_opt.calibration._plans.PATTERNS`.
    sizes : sequence of int
        Plan sizes of the coarse patterns (the physical form only up to
        :data:`MAX_PHYSICAL_POSES`; a form with more coefficients than a plan has poses
        is skipped on it).
    n_units : int
        Built units to pool over.
    seed : int
        Seed of the units, the Sobol scrambling and every noise draw.
    n_validation : int
        Validation poses per unit.
    progress : callable, optional
        ``progress(fraction, message)``, called as the units are built and each plan is
        done (:class:`reflector_opt.util._progress.Progress`).
    factory : callable, optional
        Executor factory (:mod:`reflector_opt.util._pools`); default two local processes.

    Returns
    -------
    PlanStudy
    """
    progress = no_progress if progress is None else progress
    if len(design.sensors) != 2:
        raise InputError("plan-calibration: the design must have exactly two sensors")
    unknown = sorted(set(patterns) - set(PATTERNS))
    if unknown:
        raise InputError(f"patterns: unknown {', '.join(unknown)}; known: {', '.join(PATTERNS)}")
    templates = {form: make_estimator(form, design=design, seed=seed) for form in forms}
    units, floor = _units_and_floor(design, n_units, seed, n_validation, progress)
    plans = _plans(design.workspace, patterns, sizes, seed)
    order = sorted(range(len(plans)), key=lambda i: -_cost(plans[i][1], templates.values()))
    done = run_batches(
        plan_predictions,
        (units, templates, int(n_validation), seed),
        [plans[i] for i in order],
        local_processes(2) if factory is None else factory,
        progress=lambda fraction, message: progress(
            0.1 + 0.9 * fraction, f"{round(fraction * len(plans))} of {len(plans)} plans"
        ),
    )
    by_plan = dict(zip(order, done, strict=True))
    predictions = [p for i in range(len(plans)) for p in by_plan[i]]
    return PlanStudy(predictions, floor, int(n_units), int(seed))


def recommend(study, within=0.10):
    """The smallest plan whose RMS error is within ``within`` of the floor on both angles.

    Ties in size go to the smaller worst ratio to the floor.

    Parameters
    ----------
    study : PlanStudy
    within : float
        Allowed excess over the Cramér–Rao floor (0.10: at most 1.1 × the floor).

    Returns
    -------
    PlanPrediction or None
        None if no plan comes that close.
    """
    ratio = {id(p): float(np.max(p.rms_deg / study.floor_rms_deg)) for p in study.predictions}
    good = [p for p in study.predictions if ratio[id(p)] <= 1.0 + within]
    return min(good, key=lambda p: (p.n_poses, ratio[id(p)]), default=None)


def motion_time_s(plan_or_path_deg, speed_deg_s, dwell_s=0.0, n_poses=None):
    """Time for the rig to visit a plan: path length / speed + a dwell at every pose.

    Parameters
    ----------
    plan_or_path_deg : array_like or float
        The plan's poses (n, 2), or its path length in degrees (then give ``n_poses``).
    speed_deg_s : float
        Speed along the path, degrees per second (positive).
    dwell_s : float
        Time held at each pose to settle and record, seconds.
    n_poses : int, optional
        Number of poses, when a path length is given.

    Returns
    -------
    float
        Seconds.
    """
    if not speed_deg_s > 0 or not np.isfinite(speed_deg_s):
        raise InputError(
            f"speed: must be a positive number of degrees per second, got {speed_deg_s}"
        )
    if not dwell_s >= 0 or not np.isfinite(dwell_s):
        raise InputError(f"dwell: must be a number of seconds ≥ 0, got {dwell_s}")
    if np.ndim(plan_or_path_deg) == 0:
        path, count = float(plan_or_path_deg), int(n_poses or 0)
    else:
        path, count = path_length_deg(plan_or_path_deg), len(plan_or_path_deg)
    return path / speed_deg_s + count * dwell_s


#: Predictions a display lists; the rest are counted.
SHOWN_PREDICTIONS = 15
