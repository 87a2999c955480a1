"""Summary of a design over its workspace: sensor windows and predicted calibration errors.

Every predicted calibration error is measured against built units
(:mod:`reflector_opt.tolerance._builtunit`): units drawn from the tolerance model, their optics
from the exact reference, with voltage noise and the angle reference's noise. This module
sits in the tolerance layer because that truth needs the tolerance model (docs/architecture.md).
"""

import msgspec
import numpy as np
from msgspec import UNSET, UnsetType

from reflector_opt.analysis._budget import BUDGET_STEP_DEG, drift_sensitivity, error_budget
from reflector_opt.analysis._surface import surface_comparison
from reflector_opt.calibration._misfit import form_misfit_deg
from reflector_opt.calibration._models import make_model
from reflector_opt.calibration._plans import make_plan
from reflector_opt.calibration._segment import AXES, table_one, workspace_amplitude_deg
from reflector_opt.calibration._selection import AutoModel
from reflector_opt.calibration._simulation import ErrorStats, assess
from reflector_opt.design._in_use import InUse
from reflector_opt.model._drive import DRIVES
from reflector_opt.model._forward import respond
from reflector_opt.tolerance._builtunit import (
    REFERENCE_SIGMA_DEG,
    build_unit,
    built_unit_protocol,
    crlb_floor_deg,
)
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import Record
from reflector_opt.util._progress import no_progress, scaled

#: The paper's calibration models, fitted on the paper's raster of poses.
CALIBRATION_MODELS = ("eq5", "eq6")
#: The calibration model of the paper's segment figures.
SEGMENT_MODEL = "eq6"
#: The recommended plan: a 14 × 14 grid (196 poses) with the form chosen by cross-validation
#: (``auto``); docs/calibration.md shows it within 1.2× of the Cramér–Rao floor.
RECOMMENDED_PLAN = {"pattern": "grid", "n_poses": 196}
#: Validation poses per built unit.
N_VALIDATION = 5000


class Angles(Record):
    """A figure of pitch and of roll (the unit its field's name says); ``angles["pitch"]``
    reads one by name."""

    pitch: float
    roll: float

    def __getitem__(self, axis):
        return getattr(self, axis)


def _by_angle(values):
    return Angles(pitch=float(values[0]), roll=float(values[1]))


class FormErrors(Record):
    """One calibration form's predicted error over the built units against the truth: RMS
    of the units' RMS, the largest maximum and percent = 100 × RMS / workspace span, in
    total and of the model's misfit and the noise alone; the recommended form adds the
    forms cross-validation chose (one a unit), its plan and its RMS over the floor."""

    rms_deg: Angles
    max_deg: Angles
    percent_error: Angles
    misfit_rms_deg: Angles
    noise_rms_deg: Angles
    n_calibration: int
    models: list[str] | UnsetType = UNSET
    plan: dict | UnsetType = UNSET
    floor_ratio: Angles | UnsetType = UNSET


def _form_errors(results, **recommended):
    """The errors of one model over the units (see ``CalibrationResult.to_dict``)."""
    span = results[0].protocol.span_deg

    def pooled(stats):  # RMS of the RMS, maximum of the maxima
        rms = np.sqrt(np.mean([s.rms_deg**2 for s in stats], axis=0))
        return ErrorStats(rms, np.max([s.max_deg for s in stats], axis=0), 100.0 * rms / span)

    total = pooled([r.total for r in results])
    return FormErrors(
        rms_deg=_by_angle(total.rms_deg),
        max_deg=_by_angle(total.max_deg),
        percent_error=_by_angle(total.percent),
        misfit_rms_deg=_by_angle(pooled([r.misfit for r in results]).rms_deg),
        noise_rms_deg=_by_angle(pooled([r.noise for r in results]).rms_deg),
        n_calibration=len(results[0].protocol.calibration.angles_deg),
        **recommended,
    )


class CalibrationPrediction(Record):
    """The predicted calibration of built units: how they were made and checked
    (``protocol``), their Cramér–Rao floor (RMS over the validation poses, degrees) and the
    errors of Eq 5, Eq 6 and the recommended form."""

    protocol: dict
    floor_rms_deg: Angles
    eq5: FormErrors
    eq6: FormErrors
    recommended: FormErrors


class Prediction(Record):
    """:func:`predicted_performance`: the calibration and the segment, Table-I-style
    ``{pitch, roll}.{predicted, paper}`` of Eq 6 and of the recommended form (None when the
    workspace excludes the zero pose); every block None unless the design has two sensors."""

    calibration: CalibrationPrediction | None
    segment: dict | None
    segment_recommended: dict | None


#: The units' calibration's share of :func:`predicted_performance` (the segment sweep, the rest).
UNITS_SHARE = 0.9


def predicted_performance(design, seed=0, progress=None):
    """Predicted calibration and segment errors of a design, against built units (seeded).

    Builds ``mechanics.n_units`` units (:func:`reflector_opt.tolerance._builtunit.build_unit`),
    calibrates each with the paper's Eq 5 and Eq 6 on the paper's raster of poses and with
    the recommended form (chosen by cross-validation,
    :class:`~reflector_opt.calibration._selection.AutoModel`) on the recommended plan
    (:data:`RECOMMENDED_PLAN`), and validates every fit on :data:`N_VALIDATION` random poses
    per unit with the true angles. The segment of those units is swept through the paper's
    ±60° pitch and roll motions (smaller if the workspace requires), once with each unit's
    Eq 6 and once with its recommended form.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    seed : int
    progress : callable, optional
        ``progress(fraction, message)`` as each unit is calibrated and the segment swept.

    Returns
    -------
    Prediction
        ``calibration.<eq5|eq6|recommended>`` (:class:`FormErrors`),
        ``calibration.floor_rms_deg`` and ``calibration.protocol``, ``segment`` and
        ``segment_recommended``; ``to_dict()`` is its JSON (``evaluate --json``).
    """
    if len(design.sensors) != 2:
        return Prediction(calibration=None, segment=None, segment_recommended=None)
    workspace = design.workspace
    raster = make_plan(workspace, "raster")
    needed = max(len(make_model(name).terms) for name in CALIBRATION_MODELS)
    if len(raster) < needed:  # the fit would fail, naming neither the design nor the key
        raise InputError(
            f"workspace.step_deg: {workspace.step_deg:g}° makes a calibration raster of "
            f"{len(raster)} poses, fewer than the {needed} coefficients per angle of the "
            "paper's models; give a finer step"
        )
    progress = no_progress if progress is None else progress
    results, floor, pairs = _calibrated_units(design, raster, seed, progress)
    progress(UNITS_SHARE, "segment errors of built units")
    best = results["recommended"]
    calibration = CalibrationPrediction(
        protocol={
            "truth": "built units, exact optics",
            "n_units": design.mechanics.n_units,
            "step_deg": workspace.step_deg,
            "n_calibration": len(raster),
            "n_validation": N_VALIDATION,
            "reference_sigma_deg": REFERENCE_SIGMA_DEG,
            "noise": design.noise.to_dict(),
            "seed": seed,
        },
        floor_rms_deg=_by_angle(floor),
        **{name: _form_errors(results[name]) for name in CALIBRATION_MODELS},
        recommended=_form_errors(
            best,
            models=[r.model.selected_.name for r in best],
            plan=dict(RECOMMENDED_PLAN),
            floor_ratio=_by_angle(np.sqrt(np.mean([r.total.rms_deg**2 for r in best], 0)) / floor),
        ),
    )
    segments = {"segment": None, "segment_recommended": None}
    if all(workspace_amplitude_deg(design, axis) > 0 for axis in AXES):
        for key, name in (("segment", SEGMENT_MODEL), ("segment_recommended", "recommended")):
            segments[key] = {
                "n_units": design.mechanics.n_units,
                "link_length_mm": design.mechanics.link_length_mm,
                "model": name,
                **table_one(design, None, seed=seed, units=pairs[name]),
            }
    progress(1.0, "calibration and segment errors predicted")
    return Prediction(calibration=calibration, **segments)


def _calibrated_units(design, raster, seed, progress):
    """Every built unit calibrated with the paper's models on the raster and the recommended
    form on the recommended plan: the assessments by model, the units' Cramér–Rao floor and,
    for the segment, (recorder, fitted model) pairs of Eq 6 and of the recommended form."""
    plan = make_plan(design.workspace, RECOMMENDED_PLAN["pattern"], RECOMMENDED_PLAN["n_poses"])
    results = {name: [] for name in (*CALIBRATION_MODELS, "recommended")}
    floors, pairs = [], {SEGMENT_MODEL: [], "recommended": []}
    n_units = design.mechanics.n_units
    for index in range(n_units):

        def step(k, what, index=index):  # three steps a unit
            done = UNITS_SHARE * (index + k / 3) / n_units
            progress(done, f"calibrating built unit {index + 1} of {n_units}: {what}")

        step(0, "building it (exact optics)")
        unit = build_unit(design, index, seed=seed)
        paper = built_unit_protocol(unit, raster, n_validation=N_VALIDATION, seed=seed)
        step(1, "the paper's models")
        for name in CALIBRATION_MODELS:
            results[name].append(assess(make_model(name), paper))
        step(2, "the recommended form")
        planned = built_unit_protocol(unit, plan, n_validation=N_VALIDATION, seed=seed)
        results["recommended"].append(assess(AutoModel(seed=seed), planned))
        floors.append(crlb_floor_deg(unit, planned.validation.angles_deg))

        def recorder(poses, rng, unit=unit):
            return unit.record(poses, rng, 0.0).volts

        pairs[SEGMENT_MODEL].append((recorder, results[SEGMENT_MODEL][-1].model))
        pairs["recommended"].append((recorder, results["recommended"][-1].model.selected_))
    return results, np.sqrt(np.mean(np.square(floors), axis=0)), pairs


class Extremes(Record):
    """The smallest and the largest value over the workspace grid."""

    min: float
    max: float


class SensorWindow(Record):
    """One sensor over the workspace: its part's usable range, the distance (mm) and voltage
    (V) extremes, the margin to the nearer end of the range (mm, negative outside)."""

    name: str
    model: str
    range_mm: list[float]
    distance_mm: Extremes
    volts: Extremes
    margin_mm: float
    in_range: bool


def _sensor_windows(design, response):
    """Per sensor, its :class:`SensorWindow`."""
    sensors = []
    for i, (placement, model) in enumerate(zip(design.sensors, design.models, strict=True)):
        d, v = response.distance_mm[..., i], response.volts[..., i]
        lo, hi = model.range_mm
        margin = min(float(d.min()) - lo, hi - float(d.max()))
        sensors.append(
            SensorWindow(
                name=placement.name,
                model=model.name,
                range_mm=[lo, hi],
                distance_mm=Extremes(min=float(d.min()), max=float(d.max())),
                volts=Extremes(min=float(v.min()), max=float(v.max())),
                margin_mm=margin,
                in_range=margin >= 0.0,
            )
        )
    return sensors


class Evaluation(Record, kw_only=True):
    """A design evaluated over its workspace (:func:`evaluation_summary`; ``evaluate``'s
    summary, its ``to_dict()`` the ``--json``).

    Attributes
    ----------
    in_use : reflector_opt.design._in_use.InUse
        The figures in use (set by ``evaluate``).
    workspace : dict
        The workspace's ranges and grid step, and its ``poses``.
    sensors : list of SensorWindow
    in_range : bool
        Every sensor inside its range everywhere.
    surface : dict
        The reflectance, the specular fraction and the worst-case 1σ resolution (degrees) of
        this design and of the default design in its unit against the specular fraction
        (:func:`~reflector_opt.analysis._surface.surface_comparison`).
    drift_sensitivity : dict
        ``common`` and each sensor: the angle error per 1 % change of the light path
        (:func:`~reflector_opt.analysis._budget.drift_sensitivity`).
    conditions, drive, budget, worst_case_deg, joint, assumed_figures, drive_comparison
        With conditions (:func:`conditions_summary`).
    calibration, segment, segment_recommended
        With the prediction (:class:`Prediction`).
    """

    in_use: InUse | UnsetType = UNSET
    workspace: dict
    sensors: list[SensorWindow]
    in_range: bool
    surface: dict
    drift_sensitivity: dict
    conditions: dict | UnsetType = UNSET
    drive: dict | UnsetType = UNSET
    budget: dict | UnsetType = UNSET
    worst_case_deg: float | UnsetType = UNSET
    joint: dict | UnsetType = UNSET
    assumed_figures: list | UnsetType = UNSET
    drive_comparison: dict | UnsetType = UNSET
    calibration: CalibrationPrediction | UnsetType | None = UNSET
    segment: dict | UnsetType | None = UNSET
    segment_recommended: dict | UnsetType | None = UNSET


def evaluation_summary(design, predict=True, seed=0, progress=None, conditions=None):
    """Distance and voltage range of every sensor over the design's workspace grid.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    predict : bool
        Add the predicted calibration and segment errors (:func:`predicted_performance`).
    seed : int
        Seed of the simulated calibration.
    progress : callable, optional
        ``progress(fraction, message)`` before each step
        (:class:`~reflector_opt.util._progress.Progress`).
    conditions : reflector_opt.design._conditions.Conditions, optional
        Operating conditions: add the error budget in them (:func:`conditions_summary`).

    Returns
    -------
    Evaluation
        Without ``in_use``; with ``conditions`` their blocks, with ``predict`` the
        prediction's.
    """
    progress = progress or no_progress
    progress(0.0, "distance and voltage windows")
    pitch, roll = design.workspace.grid()
    sensors = _sensor_windows(design, respond(design, pitch, roll))
    progress(0.1, "resolution against the specular fraction")
    surface = {
        "reflectance": design.reflector.reflectance,
        "specular_fraction": design.reflector.specular_fraction,
        "resolution_against_specular_fraction": surface_comparison(design),
    }
    progress(0.2, "drift sensitivity and error budget")
    blocks = conditions_summary(design, conditions)
    if predict:
        prediction = predicted_performance(design, seed=seed, progress=scaled(progress, 0.3, 1))
        blocks |= msgspec.structs.asdict(prediction)
    progress(1.0, "evaluated")
    return Evaluation(
        workspace={**design.workspace.to_dict(), "poses": int(np.broadcast(pitch, roll).size)},
        sensors=sensors,
        in_range=all(s.in_range for s in sensors),
        surface=surface,
        **blocks,
    )


def conditions_summary(design, conditions=None, form="auto"):
    """A design's drift sensitivity and, in given conditions, its error budget.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    conditions : reflector_opt.design._conditions.Conditions, optional
    form : str, optional
        The calibration form whose misfit is the budget's ``form`` source
        (:func:`~reflector_opt.calibration._misfit.form_misfit_deg`).

    Returns
    -------
    dict
        JSON-ready: ``drift_sensitivity`` (``common`` and each sensor: angle error per 1 %
        change of the light path); with ``conditions``, also ``conditions`` (the table used),
        ``drive`` (the scheme's effects, the LEDs' self-heating in K), ``budget``
        (``{SOURCE: {pitch_rms_deg, roll_rms_deg, pitch_max_deg, roll_max_deg}, …, total}``),
        ``worst_case_deg`` (:attr:`~reflector_opt.analysis._budget.ErrorBudget.worst_case_deg`),
        ``joint`` (what of the clearance the calibration learns and what stays),
        ``assumed_figures`` (every assumed figure the budget leans on, with its source) and
        ``drive_comparison`` (each drive scheme's total, worst case and frame rate in the
        same conditions, the form left out).
    """
    drift = {name: e.to_dict() for name, e in drift_sensitivity(design).items()}
    if conditions is None:
        return {"drift_sensitivity": drift}
    pitch, roll = np.meshgrid(*design.workspace.axes(BUDGET_STEP_DEG), indexing="ij")
    budget = error_budget(
        design, conditions, form_error_deg=form_misfit_deg(design, pitch, roll, form)
    )
    return {
        "drift_sensitivity": drift,
        "conditions": conditions.to_dict(),
        "drive": budget.drive.to_dict() | {"self_heating_k": list(budget.self_heating_k)},
        "budget": budget.to_dict(),
        "worst_case_deg": budget.worst_case_deg,
        "joint": budget.joint.to_dict(),
        "assumed_figures": list(budget.assumed),
        "drive_comparison": {
            scheme: _drive_row(design, conditions.replace(drive=scheme)) for scheme in DRIVES
        },
    }


def _drive_row(design, conditions):
    """Total and worst case of the budget (form left out) under one drive scheme."""
    budget = error_budget(design, conditions)
    return budget.total.to_dict() | {
        "worst_case_deg": budget.worst_case_deg,
        "frame_rate_hz": budget.drive.frame_rate_hz,
    }
