"""A calibration plan, or a plan for identification, as ``reflector-opt plan-calibration``
makes it.

For a calibration (the default), each calibration form's error is predicted against the number
and pattern of poses on built units (:func:`reflector_opt.tolerance._planning.predict_plans`),
the smallest plan within a fraction of the Cramér–Rao floor recommended with its motion time,
and the plan (``plan.csv``), the table (``plan.json``) and the curves (``plan.png``) written.
With ``temperature_range_k`` the recommended plan is extended with poses at other temperatures
(:mod:`reflector_opt.tolerance._thermalplan`; ``plan_temperature.csv``).

For identification, the D-optimal poses for a unit's as-built parameters are chosen
(:func:`reflector_opt.asbuilt._planstudy.plan_identification`), compared with Sobol points and
grids and checked on simulated units; the plan (``plan.csv``) and the table (``plan.json``)
are written. Plans are written and read by :func:`reflector_opt.calibration._files.write_plan_csv`
and :func:`~reflector_opt.calibration._files.read_plan_csv`.
"""

from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Literal

from msgspec import Meta

from reflector_opt.util._declared import Options, Seed, fields, option, takes
from reflector_opt.util._display import Printed
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import write_json
from reflector_opt.util._limits import MAX_POSES

#: Built units the predictions are averaged over unless told otherwise.
DEFAULT_UNITS = 3
#: Allowed excess over the Cramér–Rao floor of the recommended plan (a fraction).
DEFAULT_WITHIN = 0.10
#: The rig's speed along the path, degrees per second.
DEFAULT_SPEED_DEG_S = 10.0
#: The time the rig holds each pose, s.
DEFAULT_DWELL_S = 0.5
#: The calibration forms set beside a plan for identification unless told otherwise.
IDENTIFICATION_FORMS = ("auto", "physical")

#: The options only a plan for identification takes.
_IDENTIFICATION_ONLY = ("target_std", "candidate_step_deg", "truth", "check")


@dataclass(frozen=True, repr=False)
class PlanCalibrationRun(Printed):
    """A plan made by :func:`plan_calibration`, in memory; :meth:`write` writes it.

    Attributes
    ----------
    purpose : {"calibration", "identification"}
    study : reflector_opt.tolerance._planning.PlanStudy or IdentificationStudy
        The predictions the plan was chosen from (for identification an
        :class:`reflector_opt.asbuilt._planstudy.IdentificationStudy`).
    summary : dict
        ``plan.json``'s content: the table, the recommendation (with its motion time, s) and,
        when asked, the temperature study.
    writers : tuple of (str, callable)
        Each file's name and ``write(path)``, in the order they are written.
    out : pathlib.Path or None
        The output folder, once written.
    files : tuple of pathlib.Path
        Every file written (the folder's ``manifest.json`` besides; empty before
        :meth:`write`).
    """

    purpose: str
    study: object
    summary: dict
    writers: tuple = field(default=(), compare=False)
    out: Path | None = None
    files: tuple = ()

    def write(self, folder, *, command=("reflector_opt", "plan-calibration")):
        """Write plan.csv (and plan_temperature.csv), plan.json and, for a calibration,
        plan.png into ``folder``, whole or not at all.

        Returns
        -------
        PlanCalibrationRun
            This run, written: ``out`` and ``files`` filled in.
        """
        from reflector_opt.workflow._runs import written

        def write_into(work):
            for name, write in self.writers:
                write(work / name)
            return [name for name, _ in self.writers], {}

        return written(self, folder, command, write_into)

    def to_dict(self):
        """JSON-ready (``plan-calibration --json``): the summary, the folder and the files."""
        folder = None if self.out is None else str(self.out)
        return {**self.summary, "folder": folder, "files": [str(f) for f in self.files]}

    def text(self):
        """The tables and the recommendation, as the command prints them."""
        from reflector_opt.workflow._plan_text import format_identification, format_summary

        if self.purpose == "identification":
            return format_identification(self.summary)
        return format_summary(self.summary)


class PlanCalibrationOptions(Options):
    """The options of ``reflector-opt plan-calibration``, declared once."""

    purpose: option(
        Literal["calibration", "identification"],
        "plan a calibration's poses, or an as-built identification's",
        flag="--for",
    ) = "calibration"
    forms: option(
        tuple[str, ...] | None,
        "the calibration forms compared, comma-separated; eq6,auto,physical if left out (for "
        "identification the forms set beside it, auto,physical)",
    ) = None
    patterns: option(
        tuple[str, ...] | None,
        "the pose patterns compared, comma-separated; raster,grid,sobol,spiral if left out "
        "(for identification d-optimal,sobol,grid)",
    ) = None
    sizes: option(
        tuple[Annotated[int, Meta(ge=4, le=MAX_POSES)], ...] | None,
        "the pose counts compared, comma-separated; 25,50,100,200,400,1000,4000,16000 if "
        "left out (for identification 25,50,100,200)",
    ) = None
    units: option(int, "built units the predictions are made on", metavar="N", ge=1, le=100) = (
        DEFAULT_UNITS
    )
    seed: option(Seed, "seed of the units, the noise and the Sobol plans") = 0
    within: option(
        float,
        "allowed excess over the Cramér–Rao floor of the recommended plan (0.10: 10 %)",
        metavar="X",
        ge=0,
        le=10,
    ) = DEFAULT_WITHIN
    temperature_range_k: (
        option(
            float,
            "calibration: also plan the poses at other temperatures for a unit used within ±K "
            "kelvin of its calibration temperature (a simulation on built units; the "
            "recommended plan's form, auto for physical)",
            flag="--temperature-range",
            metavar="K",
            ge=1,
            le=60,
        )
        | None
    ) = None
    speed_deg_s: option(
        float,
        "rig speed along the path, degrees per second",
        flag="--speed",
        metavar="DEG_S",
        gt=0,
        le=1e4,
    ) = DEFAULT_SPEED_DEG_S
    dwell_s: option(
        float, "time held at each pose, seconds", flag="--dwell", metavar="S", ge=0, le=3600
    ) = DEFAULT_DWELL_S
    target_std: (
        option(
            float,
            "identification: the posterior std to reach, a fraction of the prior std; 0.5 if "
            "left out",
            metavar="X",
            gt=0,
            le=1,
        )
        | None
    ) = None
    candidate_step_deg: (
        option(
            float,
            "identification: step of the candidate grid, degrees; 1 if left out",
            flag="--candidate-step",
            metavar="DEG",
            ge=0.25,
            le=15,
        )
        | None
    ) = None
    truth: option(
        Literal["built", "model"] | None,
        "identification: check on built units with exact optics (built, the default) or on "
        "units of the identification's own model",
    ) = None
    check: option(
        bool | None,
        "check the plan by identifying simulated units, beside the Fisher prediction "
        "(identification only)",
        flag="--no-check",
    ) = None


@takes(PlanCalibrationOptions)
def plan_calibration(design=None, options=None, progress=None):
    """Plan a calibration's (or an identification's) poses, in memory: ``reflector-opt
    plan-calibration``; :meth:`PlanCalibrationRun.write` writes the plan.

    Parameters
    ----------
    design : reflector_opt.design._design.Design, str, pathlib.Path or None
        The design or its ``design.json``; None for the built-in design.
    options : PlanCalibrationOptions
        As keyword arguments (below); the identification's target std defaults to
        :data:`reflector_opt.asbuilt._uncertainty.DETERMINED_RATIO`.
    progress : callable, optional
        ``progress(fraction, message)`` as the work advances.

    Returns
    -------
    PlanCalibrationRun

    Raises
    ------
    InputError
        An option of the other purpose (named as the command's option), or a design that
        cannot be read.
    """
    import msgspec

    from reflector_opt.design import as_design

    purpose = options.purpose
    options = msgspec.structs.asdict(options) | {"progress": progress}
    if purpose == "identification":
        if options["temperature_range_k"] is not None:
            raise InputError("--temperature-range applies to --for calibration only")
    else:
        flags = {f.name: f.flag for f in fields(PlanCalibrationOptions)}
        for key in _IDENTIFICATION_ONLY:
            if options[key] is not None:
                raise InputError(f"{flags[key]} applies to --for identification only")
    options["design"] = as_design(design)
    plan = _identification if purpose == "identification" else _calibration
    return PlanCalibrationRun(purpose, *plan(options))


def _calibration(options):
    """The calibration plan: the predictions, the summary (recommendation, temperature
    study) and the files' writers."""
    from reflector_opt.calibration._files import write_plan_csv
    from reflector_opt.calibration._plans import PATTERNS, make_plan
    from reflector_opt.report._plots import calibration_plan_figure, save_figure
    from reflector_opt.tolerance._planning import FORMS, SIZES, predict_plans, recommend

    design, progress = options["design"], options["progress"]
    study = predict_plans(
        design,
        forms=options["forms"] or FORMS,
        patterns=options["patterns"] or PATTERNS,
        sizes=options["sizes"] or SIZES,
        n_units=options["units"],
        seed=options["seed"],
        progress=progress,
    )
    best = recommend(study, options["within"])
    thermal = _plan_temperature(design, study, options)
    summary = study.to_dict()
    summary["recommended"] = None
    writers = []
    if best is not None:
        plan = make_plan(design.workspace, best.pattern, best.n_poses, options["seed"])
        summary["recommended"] = {
            **best.to_dict(study.floor_rms_deg),
            **_motion(plan, options),
        }
        writers.append(("plan.csv", lambda path: write_plan_csv(path, plan)))
    if options["temperature_range_k"] is not None:  # None: no recommended plan to extend
        summary["temperature"], poses = (
            (None, None) if thermal is None else _temperature(*thermal, options)
        )
        if poses is not None:
            writers.append(
                (
                    "plan_temperature.csv",
                    lambda path: write_plan_csv(path, poses[:, :2], poses[:, 2]),
                )
            )
    writers.append(("plan.json", lambda path: write_json(path, summary)))
    writers.append(("plan.png", lambda path: save_figure(calibration_plan_figure(study), path)))
    return study, summary, tuple(writers)


def _motion(plan, options):
    """The rig's speed and dwell and the plan's motion time, s (the summary's keys)."""
    from reflector_opt.tolerance._planning import motion_time_s

    speed, dwell = options["speed_deg_s"], options["dwell_s"]
    seconds = motion_time_s(plan, speed, dwell)
    return {"speed_deg_s": speed, "dwell_s": dwell, "motion_time_s": seconds}


def _plan_temperature(design, study, options):
    """The temperature study on the plan to extend and the thermometer's costs on its layout
    at both ends, or None (not asked, or no plan)."""
    if options["temperature_range_k"] is None:
        return None
    from reflector_opt.calibration._plans import make_plan
    from reflector_opt.tolerance._thermalplan import (
        plan_temperature,
        plan_to_extend,
        thermometer_costs,
        thermometer_layout,
    )

    chosen = plan_to_extend(study, options["within"])
    if chosen is None:
        return None
    form, pattern, n_poses = chosen
    base = make_plan(design.workspace, pattern, n_poses, seed=options["seed"])
    same = {"form": form, "n_units": options["units"], "seed": options["seed"]}
    progress = options["progress"]
    thermal = plan_temperature(
        design,
        base,
        change_k=options["temperature_range_k"],
        pattern=pattern,
        progress=progress,
        **same,
    )
    layout = thermometer_layout(thermal, options["within"])
    costs = layout and thermometer_costs(design, base, layout, progress=progress, **same)
    return thermal, costs


def _temperature(study, costs, options):
    """The temperature study's summary, JSON-ready, and the poses of plan_temperature.csv
    (pitch, roll in degrees and the temperature change in K; None if no layout is
    recommended)."""
    from reflector_opt.tolerance._thermalplan import recommend_thermal, thermal_poses

    summary = study.to_dict()
    pick = recommend_thermal(study, options["within"])
    summary["recommended"] = poses = None
    if pick is not None:
        poses = thermal_poses(options["design"], pick, options["seed"])
        per_temperature = _motion(poses[: pick.n_poses, :2], options)["motion_time_s"]
        summary["recommended"] = {
            **pick.to_dict(),
            "motion_time_s": per_temperature * len(pick.changes_k),
        }
    summary["thermometer"] = costs and costs.to_dict()
    return summary, poses


def _identification(options):
    """The plan for identification: the study, the summary and the writers of plan.csv and
    plan.json."""
    from reflector_opt.calibration._files import write_plan_csv

    check = options["check"] is not False
    truth = options["truth"] or "built"
    if options["forms"] is not None and not (check and truth == "built"):
        raise InputError("--forms: the calibration forms are compared on built units only")
    study = _plan_identification(options, check, truth)
    summary = study.to_dict(options["within"])
    writers = []
    if study.plan is not None:
        plan = study.plan.poses_deg
        summary["recommended"].update(_motion(plan, options))
        writers.append(("plan.csv", lambda path: write_plan_csv(path, plan)))
    writers.append(("plan.json", lambda path: write_json(path, summary)))
    return study, summary, tuple(writers)


def _plan_identification(options, check, truth):
    """:func:`~reflector_opt.asbuilt._planstudy.plan_identification` with the run's options;
    its step messages shown through ``progress``."""
    from reflector_opt.asbuilt._patterns import PATTERNS, SIZES
    from reflector_opt.asbuilt._planstudy import plan_identification
    from reflector_opt.asbuilt._poses import CANDIDATE_STEP_DEG
    from reflector_opt.asbuilt._uncertainty import DETERMINED_RATIO

    forms = options["forms"] if options["forms"] is not None else IDENTIFICATION_FORMS
    progress = options["progress"]
    return plan_identification(
        options["design"],
        sizes=options["sizes"] or SIZES,
        patterns=options["patterns"] or PATTERNS,
        target=DETERMINED_RATIO if options["target_std"] is None else options["target_std"],
        n_units=options["units"] if check else 0,
        seed=options["seed"],
        truth=truth,
        compare_forms=forms if check and truth == "built" else (),
        candidate_step_deg=options["candidate_step_deg"] or CANDIDATE_STEP_DEG,
        progress=None if progress is None else lambda message: progress(0.0, message),
    )
