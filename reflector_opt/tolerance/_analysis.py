"""Monte Carlo analysis of one design: build, calibrate and assess each sampled unit.

For every sample the as-built unit (:func:`reflector_opt.tolerance._tolerances.as_built`) goes
through the paper's calibration protocol as :mod:`~.simulation` simulates it — a
grid of poses over the workspace, Eq 6 (or another model) fitted to the recorded voltages,
validation on independent uniformly random poses with fresh noise — but with the as-built
unit's read-out:

1. noise-free voltages V_i of the as-built geometry (:func:`reflector_opt.model._forward.voltages`);
2. optical crosstalk in the current domain: sensor i's phototransistor also collects the
   fraction k_i of every other sensor's light-induced current,
   ``V_i' = V_i − k_i · Σ_{j≠i} (Vcc − V_j − I_dark·R2)``, clamped to [V_CE(sat), Vcc];
3. in use only (validation): an ambient-light collector current I_amb,
   ``V_i'' = V_i' − I_amb · R2``, clamped likewise;
4. gain and offset (:class:`reflector_opt.model._noise.Mismatch`), electrical noise and the ADC
   (:func:`reflector_opt.calibration._simulation.measure_with_design_noise`).

The calibration is fitted on the as-built unit, so it absorbs what is stable and smooth (most
of a geometric error, gain, offset, steady crosstalk); what it does not absorb shows as the
validation error. Per sample this records the distance window (kept when every sensor stays in
its usable range over the workspace), the worst-case Cramér–Rao resolution
(:func:`~.metrics.evaluate_metrics` on a coarse grid), the thinnest shell wall, and
the calibrated RMS and maximum error of pitch and roll.
"""

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Annotated, Literal

import numpy as np
from msgspec import Meta

from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.calibration._models import make_model
from reflector_opt.calibration._simulation import (
    Samples,
    assess,
    measure_with_design_noise,
    simulate_protocol,
    validation_error,
)
from reflector_opt.model._forward import voltages
from reflector_opt.tolerance._tolerances import Tolerances, as_built, drawn_errors
from reflector_opt.util import _schema as schema
from reflector_opt.util._errors import FitError, InputError
from reflector_opt.util._limits import (
    MAX_ANGLE_DEG,
    MAX_POSE_EVALUATIONS,
    MAX_POSES,
    MAX_SIMULATED_UNITS,
    check_size,
)

#: The record's columns that :func:`_geometry_outputs` fills.
_GEOMETRY_COLUMNS = ("window_kept", "distance_margin_mm")
_GEOMETRY_COLUMNS += ("resolution_pitch_deg", "resolution_roll_deg", "wall_min_mm")

#: The calibrated errors of a record: RMS and maximum, of pitch and of roll.
_ERRORS = tuple(f"{kind}_{angle}_deg" for kind in ("rms", "max") for angle in ("pitch", "roll"))

#: The record's columns that :func:`_calibration_outputs` fills (besides ``status``).
_CALIBRATION_COLUMNS = (*_ERRORS, "misfit_rms_deg")

#: The performance figures of a record whose distributions a study reports.
METRIC_COLUMNS = (*_GEOMETRY_COLUMNS[1:], *_ERRORS)
#: Columns every result record has, in CSV order (after ``index`` and the draw columns).
OUTPUT_COLUMNS = ("status", "window_kept", *METRIC_COLUMNS, "misfit_rms_deg")


#: Grid step of the global uniqueness check inside :func:`evaluate_metrics` when the metrics
#: grid is finer than 1°, degrees. The check is not part of a sample's record, so it runs on
#: a coarse grid (its cost grows with the square of the number of poses).
UNIQUENESS_STEP_DEG = 5.0


@dataclass(frozen=True)
class Settings:
    """How each sample is calibrated and assessed.

    Parameters
    ----------
    calibration_step_deg : float
        Step of the calibration pose grid, degrees (the paper used 0.1°).
    n_validation : int
        Validation poses per sample.
    metrics_step_deg : float
        Grid step of the distance window and resolution, degrees.
    model : str
        Calibration model: ``"eq5"``, ``"eq6"`` or ``"polyN"``.
    fit : {"lsq", "huber", "minimax"}
    calibrate : bool
        Simulate each unit's calibration and validation. Without it only the geometry is
        assessed (distance window, resolution, wall): about 2.5× faster per unit, the record's
        status is ``"uncalibrated"`` and its calibrated errors are NaN; the yield then counts
        the distance window alone.
    """

    calibration_step_deg: float = 0.5
    n_validation: int = 2000
    metrics_step_deg: float = 1.0
    model: str = "eq6"
    fit: str = "lsq"
    calibrate: bool = True

    def __post_init__(self):
        """Check every field against ``[settings]``'s declaration (:class:`SettingsTable`),
        the one place its ranges are stated, and the model's and fit's names."""
        schema.convert(dataclasses.asdict(self), SettingsTable)
        # names checked now, not in a worker, each message under its key
        for key, args in (("model", (self.model,)), ("fit", (self.model, self.fit))):
            try:
                make_model(*args)
            except InputError as exc:
                raise InputError(f"{key}: {exc}") from None

    def template(self):
        """The unfitted calibration model."""
        return make_model(self.model, self.fit)

    def poses_per_unit(self, workspace):
        """Poses at which the model is evaluated for one unit over ``workspace``.

        The metrics grid with its central-difference stencil (5 poses each) and, with
        ``calibrate``, the calibration grid and the validation poses. Each grid is refused if
        it is too large (:meth:`~reflector_opt.design._components.Workspace.check_step`).

        Parameters
        ----------
        workspace : reflector_opt.design._components.Workspace

        Returns
        -------
        int
        """
        poses = 5 * workspace.check_step(self.metrics_step_deg, "settings.metrics_step_deg")
        if self.calibrate:
            poses += workspace.check_step(
                self.calibration_step_deg, "settings.calibration_step_deg"
            )
            poses += self.n_validation
        return poses


@dataclass(frozen=True)
class Targets:
    """What a built unit must achieve to count towards the yield.

    Parameters
    ----------
    window : bool
        Every sensor stays inside its usable distance range over the workspace.
    rms_deg : float
        Largest calibrated RMS error of pitch and of roll, degrees.
    max_deg : float
        Largest calibrated maximum error of pitch and of roll, degrees.
    """

    window: bool = True
    rms_deg: float = 1.0
    max_deg: float = 3.0

    def __post_init__(self):
        """Check every field against ``[targets]``'s declaration (:class:`TargetsTable`)."""
        schema.convert(dataclasses.asdict(self), TargetsTable, where="targets")

    def to_dict(self):
        """JSON-ready dict."""
        return {"window": self.window, "rms_deg": self.rms_deg, "max_deg": self.max_deg}


Step = Annotated[float, Meta(gt=0, le=MAX_ANGLE_DEG, description="a pose grid step, degrees")]
Error = Annotated[float, Meta(gt=0, le=2 * MAX_ANGLE_DEG, description="an angle error, degrees")]


class SettingsTable(schema.Table):
    """``[settings]``: how each sample is calibrated and assessed."""

    # Each key's range is declared here once: Settings is checked against it too.

    calibration_step_deg: Step = Settings.calibration_step_deg
    n_validation: Annotated[int, Meta(ge=1, le=MAX_POSES, description="validation poses")] = (
        Settings.n_validation
    )
    metrics_step_deg: Step = Settings.metrics_step_deg
    model: Annotated[str, Meta(description='"eq5", "eq6" or "polyN"')] = Settings.model
    fit: Literal["lsq", "huber", "minimax"] = Settings.fit
    calibrate: bool = Settings.calibrate


class TargetsTable(schema.Table):
    """``[targets]``: what a built unit must achieve to count towards the yield."""

    window: bool = Targets.window
    rms_deg: Error = Targets.rms_deg
    max_deg: Error = Targets.max_deg


def check_work(workspace, settings, units, where):
    """Refuse a study or sweep beyond the limits of one run, before any work starts.

    Parameters
    ----------
    workspace : reflector_opt.design._components.Workspace
    settings : Settings
    units : int
        Simulated units in all (samples, sensitivity runs, sweep points).
    where : str
        The parameters that set ``units``, for the message.

    Returns
    -------
    int
        The pose evaluations of the run. Raises
        :class:`~reflector_opt.util._errors.InputError` naming the parameters when the units
        exceed :data:`~reflector_opt.util._limits.MAX_SIMULATED_UNITS`, a grid exceeds
        :data:`~reflector_opt.util._limits.MAX_POSES` or units × poses per unit exceed
        :data:`~reflector_opt.util._limits.MAX_POSE_EVALUATIONS`.
    """
    check_size(units, where, MAX_SIMULATED_UNITS, "simulated units")
    poses = settings.poses_per_unit(workspace)
    return check_size(
        units * poses,
        f"{where} ({units:,} units × {poses:,} poses each)",
        MAX_POSE_EVALUATIONS,
        "model evaluations",
    )


@dataclass(frozen=True)
class Job:
    """Everything a worker needs besides the draws: sent once per batch.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        The nominal design.
    tolerances : Tolerances
    settings : Settings
    full : bool
        Record every output (the default). False records the calibrated errors alone — the
        output a sensitivity analysis ranks (:func:`~reflector_opt.tolerance._study.output_of`)
        — without the geometry's metrics (distance window, resolution, wall: NaN) and
        without the noise-free misfit fit (NaN): about a third cheaper a unit, and the
        calibrated errors are the same as a full record's for the same draw.
    """

    design: object
    tolerances: Tolerances = field(default_factory=Tolerances)
    settings: Settings = field(default_factory=Settings)
    full: bool = True


def read_out(design, electrical, volts, *, in_use):
    """Noise-free voltages of the as-built read-out: crosstalk and, in use, ambient light.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        The as-built design (its sensor models give Vcc, R2, dark current, V_CE(sat)).
    electrical : reflector_opt.tolerance._tolerances.Electrical
    volts : numpy.ndarray
        Shape (n, n_sensors): forward-model voltages, V.
    in_use : bool
        Add the ambient-light current (validation poses), not during calibration.

    Returns
    -------
    numpy.ndarray
        Shape (n, n_sensors), V; equal to ``volts`` when crosstalk and ambient are zero.
    """
    models = design.models
    vcc = np.array([m.supply_v for m in models])
    load = np.array([m.load_resistor_ohm for m in models])
    light = vcc - volts - np.array([m.dark_current_a for m in models]) * load  # I_light · R2
    from_others = (light.sum(axis=-1, keepdims=True) - light) / load  # Σ_{j≠i} I_light,j
    drop = electrical.crosstalk_fraction * from_others * load
    if in_use:
        drop = drop + electrical.ambient_current_ua * 1e-6 * load
    low = np.array([m.saturation_v for m in models])
    return np.clip(volts - drop, low, vcc)


#: The tolerances that change a unit's optics (its forward-model voltages); the inner radius
#: changes only the shell wall, the others only the read-out.
OPTICS_TOLERANCES = (
    "reflector_radius_mm",
    "centre_offset_mm",
    "sensor_position_mm",
    "sensor_tilt_deg",
)


class _SharedForward:
    """The forward model's voltages of the units of one batch, computed once per optics.

    Units of one job whose drawn errors agree on :data:`OPTICS_TOLERANCES` are the same
    geometry: their voltages on the calibration grid are the same, and on the validation
    poses too when their noise seed (which draws those poses) is the same. That is the case
    of a Sobol row's AB rows for the read-out tolerances, the inner radius and the noise, and
    of the one-at-a-time runs of tolerances that leave the optics alone.
    """

    def __init__(self):
        self.volts = {}

    def __call__(self, design, angles, key):
        if key not in self.volts:
            self.volts[key] = voltages(design, angles[:, 0], angles[:, 1])
        return self.volts[key]


def _protocol(design, electrical, settings, seed, forward=None, optics=None):
    """The simulated calibration protocol
    (:func:`reflector_opt.calibration._simulation.simulate_protocol`) on the workspace grid
    with the as-built read-out: crosstalk always, ambient light in use.

    ``forward`` (a :class:`_SharedForward`) and ``optics`` (the key of the unit's optics)
    reuse the voltages of a unit of the same optics computed before in the batch.
    """
    if forward is None:
        forward, optics = _SharedForward(), None
    mismatch = electrical.mismatch

    def recorder(angles, rng, in_use):
        key = ("validation", seed, optics) if in_use else ("grid", optics)
        volts = forward(design, angles, key)
        true = read_out(design, electrical, volts, in_use=False)
        seen = read_out(design, electrical, volts, in_use=True) if in_use else true
        return Samples(angles, true, measure_with_design_noise(design, seen, rng, mismatch))

    step = settings.calibration_step_deg
    workspace = design.workspace
    return simulate_protocol(
        recorder,
        workspace,
        workspace.poses(step),
        settings.n_validation,
        np.random.default_rng(seed),
        step_deg=step,
        seed=seed,
    )


def draw_columns(n_sensors, sensor_names=None):
    """Names of the columns holding a sample's drawn errors, in :func:`evaluate_draw` order."""
    names = sensor_names or [f"S{i + 1}" for i in range(n_sensors)]
    per = {
        "reflector_radius_mm": ["d_reflector_radius_mm"],
        "centre_offset_mm": [f"d_centre_{c}_mm" for c in "xyz"],
        "inner_radius_mm": ["d_inner_radius_mm"],
        "sensor_position_mm": [f"d_{s}_{c}_mm" for s in names for c in "xyz"],
        "sensor_tilt_deg": [f"{s}_tilt_{c}_deg" for s in names for c in "uw"],
        "gain": [f"{s}_gain_error" for s in names],
        "offset_v": [f"{s}_offset_v" for s in names],
        "crosstalk_fraction": [f"{s}_crosstalk_fraction" for s in names],
        "ambient_current_ua": [f"{s}_ambient_current_ua" for s in names],
    }
    return [c for name in Tolerances.names() for c in per[name]]


def evaluate_draw(job, draw, forward=None):
    """Build, calibrate and assess the unit of one draw.

    Parameters
    ----------
    job : Job
    draw : reflector_opt.tolerance._tolerances.Draw
    forward : _SharedForward, optional
        Voltages already computed in this batch for units of the same optics (reused: the
        record is the same as without).

    Returns
    -------
    dict
        ``index``, the drawn errors (:func:`draw_columns`) and :data:`OUTPUT_COLUMNS`.
        ``status`` is ``"ok"``, ``"invalid"`` (the as-built unit is not a valid design, e.g. a
        sensor inside the sphere: the window counts as lost, every output is NaN) or
        ``"unfit"`` (its voltages do not determine the calibration model, e.g. saturated
        outputs: the calibrated errors are NaN) or, with ``Settings.calibrate`` false,
        ``"uncalibrated"`` (geometry only: the calibrated errors are NaN). Only ``"ok"``
        units can pass every target; ``"uncalibrated"`` ones are judged by the window alone.
    """
    design = job.design
    record = {"index": draw.index}
    drawn = drawn_errors(job.tolerances, draw)
    record.update(
        zip(
            draw_columns(len(design.sensors), [s.name for s in design.sensors]),
            np.concatenate(list(drawn.values())).tolist(),
            strict=True,
        )
    )
    nan = math.nan
    try:
        built, electrical = as_built(design, job.tolerances, draw)
    except InputError:
        record.update(dict.fromkeys(OUTPUT_COLUMNS, nan))
        record.update(status="invalid", window_kept=False)
        return record
    settings = job.settings
    if job.full:
        record.update(_geometry_outputs(built, settings))
    else:
        record.update(dict.fromkeys(_GEOMETRY_COLUMNS, nan))
    if not settings.calibrate:
        record.update(dict.fromkeys(_CALIBRATION_COLUMNS, nan), status="uncalibrated")
        return record
    optics = tuple((drawn[name] + 0.0).tobytes() for name in OPTICS_TOLERANCES)  # -0 is 0
    record.update(_calibration_outputs(job, built, electrical, draw, forward, optics))
    return record


def _calibration_outputs(job, built, electrical, draw, forward, optics):
    """``status`` (``"ok"`` or ``"unfit"``) and the calibrated errors of an as-built unit."""
    try:
        protocol = _protocol(built, electrical, job.settings, draw.noise_seed, forward, optics)
        total, misfit = _calibrated_errors(job.settings.template(), protocol, job.full)
    except FitError:
        return {**dict.fromkeys(_CALIBRATION_COLUMNS, math.nan), "status": "unfit"}
    return {
        "status": "ok",
        "rms_pitch_deg": float(total.rms_deg[0]),
        "rms_roll_deg": float(total.rms_deg[1]),
        "max_pitch_deg": float(total.max_deg[0]),
        "max_roll_deg": float(total.max_deg[1]),
        "misfit_rms_deg": math.nan if misfit is None else float(np.max(misfit.rms_deg)),
    }


def _geometry_outputs(built, settings):
    """Distance window, worst resolution and thinnest wall of an as-built unit.

    The metrics' global uniqueness check is not recorded: on a metrics grid of 1° or coarser
    it reuses the grid's own voltages (no forward-model run of its own), on a finer one it
    runs on :data:`UNIQUENESS_STEP_DEG` (its cost grows with the square of the poses).
    """
    step = settings.metrics_step_deg
    metrics = evaluate_metrics(
        built, step, uniqueness_step_deg=step if step >= 1.0 else UNIQUENESS_STEP_DEG
    )
    margin = float(np.min(metrics.distance_margin_mm))
    return dict(
        zip(
            _GEOMETRY_COLUMNS,
            (
                bool(margin >= 0),
                margin,
                metrics.worst_pitch_deg,
                metrics.worst_roll_deg,
                metrics.wall_min_mm,
            ),
            strict=True,
        )
    )


def _calibrated_errors(template, protocol, with_misfit):
    """Validation errors of the calibration fitted to the recorded data (ErrorStats), and
    with ``with_misfit`` those of the fit to the noise-free data (else None)."""
    if with_misfit:
        result = assess(template, protocol)
        return result.total, result.misfit
    return validation_error(template, protocol)[1], None


#: Coarsest workspace step the as-built units are checked for collisions on, degrees.
COLLISION_CHECK_STEP_DEG = 0.5


def evaluate_draws(job, draws):
    """:func:`evaluate_draw` over a batch (the unit of work sent to an executor).

    Every grid used here has an explicit step, so the design's own workspace step serves only
    the collision check each as-built unit passes on construction; it is coarsened to
    :data:`COLLISION_CHECK_STEP_DEG` (the check :class:`~.Design` runs for a
    coarse workspace anyway) rather than re-run on a 0.1° grid per sample.
    """
    workspace = job.design.workspace
    if workspace.step_deg < COLLISION_CHECK_STEP_DEG:
        coarse = dataclasses.replace(workspace, step_deg=COLLISION_CHECK_STEP_DEG)
        job = dataclasses.replace(job, design=job.design.replace(workspace=coarse))
    forward = _SharedForward()  # for this batch: one job, one design
    return [evaluate_draw(job, d, forward) for d in draws]


def evaluate_part(context, part):
    """Entry point of :func:`~reflector_opt.util._pools.run_batches`: ``part`` is
    ``(job, draws)``; ``context`` is unused (every batch carries its own job)."""
    return evaluate_draws(*part)


#: Statuses of a unit assessed as asked: calibrated, or its geometry alone when the
#: calibration is skipped (``Settings.calibrate`` false).
ASSESSED = ("ok", "uncalibrated")


def passes(record, targets):
    """Whether one result record meets the targets (NaN errors never do).

    An ``"uncalibrated"`` record (``Settings.calibrate`` false) is judged by the distance
    window alone.
    """
    if record["status"] not in ASSESSED:
        return False
    if targets.window and not record["window_kept"]:
        return False
    if record["status"] == "uncalibrated":
        return True
    rms = max(record["rms_pitch_deg"], record["rms_roll_deg"])
    worst = max(record["max_pitch_deg"], record["max_roll_deg"])
    return bool(rms <= targets.rms_deg and worst <= targets.max_deg)
