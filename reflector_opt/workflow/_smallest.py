"""The smallest unit for an accuracy target, as ``reflector-opt smallest`` makes it: the
size–accuracy frontier of each sensor part over the catalogue's bearings
(:mod:`reflector_opt.optimiser._size`), the smallest unit meeting the target, and its design,
written into one output folder with the frontier as a table and a figure. With a segment's
range, the unit's workspace is its share with the fewest units the bearings permit, and the
choices of units are judged by the tip error built units predict
(:mod:`reflector_opt.optimiser._segment_choice`)."""

import csv
import dataclasses
import io
import math
import typing
from dataclasses import dataclass, replace
from pathlib import Path

from reflector_opt.util._declared import ConditionsFile, Options, Starts, option, takes
from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import MAX_ANGLE_DEG, MAX_LENGTH_MM, OBJECTIVES
from reflector_opt.util._progress import no_progress, scaled
from reflector_opt.workflow._options import OptimiseOptions, prepare

#: The most numbers of units judged for a segment (each builds and calibrates its units).
MAX_SEGMENT_CHOICES = 10

#: The share of the run's progress before its parts are built and checked.
PARTS_SHARE = 0.9

#: The command recorded in an output folder's manifest when the library wrote it.
LIBRARY_COMMAND = ("reflector_opt", "smallest")


#: The declarations ``smallest`` shares with ``optimise``.
_OPTIMISE = typing.get_type_hints(OptimiseOptions, include_extras=True)
_Objective, _Config, _Seed, _Workers = (
    _OPTIMISE[name] for name in ("objective", "config", "seed", "workers")
)


def _Length(help):
    return option(float, help, gt=0, le=MAX_LENGTH_MM)


class SmallestOptions(Options):
    """The options of ``reflector-opt smallest``, declared once; ``conditions``, ``config``,
    ``objective``, ``seed``, ``workers`` and ``scheduler`` as for ``optimise``
    (:class:`~reflector_opt.workflow._options.OptimiseOptions`)."""

    target_deg: option(
        float,
        "the in-use worst-case total error to meet in the conditions, degrees (at least the "
        "angle reference's zero, 1° for the default imu-lpms-b); with --objective resolution "
        "the worst-case white-noise resolution with the isotropy weight",
        metavar="X",
        gt=0,
        lt=MAX_ANGLE_DEG,
    )
    objective: _Objective = OBJECTIVES[0]
    sensor: option(str, "parts: auto, names or PARTS.toml files, by commas", metavar="PARTS") = (
        "auto"
    )
    conditions: option(
        ConditionsFile,
        "operating conditions: meet the target in them; the default conditions if left out",
    ) = None
    config: _Config = None
    workspace_deg: (
        option(
            float,
            "pitch and roll range ±W, degrees; the config's if left out",
            metavar="W",
            gt=0,
            lt=MAX_ANGLE_DEG,
        )
        | None
    ) = None
    segment_range_deg: (
        option(
            float,
            "a segment's range ±R at the tip, degrees: the unit's workspace is ±R/N with the "
            "fewest units N the catalogue's bearings permit; not with --workspace-deg",
            metavar="R",
            gt=0,
            le=360,
        )
        | None
    ) = None
    link_mm: (
        option(
            float,
            "distance between the units' rotation centres, mm; the mechanics' (18) if left out",
            metavar="L",
            gt=0,
            le=MAX_LENGTH_MM,
        )
        | None
    ) = None
    segment_choices: option(
        int,
        "numbers of units judged, from the fewest up",
        metavar="K",
        ge=1,
        le=MAX_SEGMENT_CHOICES,
    ) = 3
    largest_mm: _Length("the frontier's first diameter, mm") = 22.0
    step_mm: _Length("the frontier's step down, mm") = 2.0
    resolution_mm: _Length("the resolution of the frontier's edges, mm") = 0.5
    seed: _Seed = None
    starts: option(Starts, "independent searches of each size, the best kept") = 3
    workers: _Workers = None
    scheduler: option(
        str | None,
        "Dask scheduler address for the frontier and the segment choices",
        metavar="ADDRESS",
    ) = None


@dataclass(frozen=True)
class SmallestRun:
    """What :func:`smallest` found, in memory; :meth:`write` writes it.

    Attributes
    ----------
    chosen : dict
        The frontier row of the smallest unit meeting the target.
    design : reflector_opt.design._design.Design
        Its design; ``predicted["size_frontier"]`` holds the target, the chosen row and the
        frontier.
    rows : tuple of dict
        The frontier, part by part, largest diameter first.
    segment : dict or None
        With a segment's range, ``design.predicted["segment_choice"]``: ``range_deg``,
        ``link_mm``, the ``chosen`` row, its ``errors``
        (:func:`~reflector_opt.optimiser._segment_choice.tip_errors`) and every ``choices``
        row; the design is the chosen segment's unit.
    parts : reflector_opt.workflow._export.ExportRun or None
        The design's printable parts, checked as ``reflector-opt export`` checks them
        (printability, clearance over the workspace, the Eq 3 ray check); written by
        :meth:`write`.
    limits : tuple of dict
        Per part, the smallest size any design fits and what fails below it
        (:func:`~reflector_opt.optimiser._size.size_limits`).
    out : pathlib.Path or None
        The output folder, once written.
    files : tuple of pathlib.Path
        Every file written (empty before :meth:`write`).
    """

    chosen: dict
    design: object
    rows: tuple
    segment: dict | None = None
    parts: object = None
    limits: tuple = ()
    out: Path | None = None
    files: tuple = ()

    def write(self, folder, *, command=LIBRARY_COMMAND):
        """Write ``design.json`` (the frontier in ``predicted["size_frontier"]``),
        ``frontier.csv``, ``frontier.png``, with a segment ``segment.csv``, and the design's
        printable parts, their pictures, CAD report and 3D view as ``reflector-opt export
        DIR/design.json`` writes them, into ``folder``, whole or not at all.

        Parameters
        ----------
        folder : str or pathlib.Path
        command : sequence of str, optional
            The command line recorded in the folder's manifest.

        Returns
        -------
        SmallestRun
            This run, written: ``out``, ``files`` and ``parts`` (written) filled in.
        """
        from reflector_opt.workflow._export import export_names, write_checked_parts
        from reflector_opt.workflow._runs import written

        def write_into(work):
            names = _write(work, self.design, self.rows, self.segment)
            p = self.parts
            report = write_checked_parts(p.parts, work, p.params, p.preview, None)
            return [*names, *export_names(report)], {"parts": replace(p, report=report)}

        run = written(self, folder, command, write_into)
        parts_files = tuple(run.out / name for name in export_names(run.parts.report))
        return replace(run, parts=replace(run.parts, out=run.out, files=parts_files))

    def to_dict(self):
        """JSON-ready summary (the command's ``--json``)."""
        return {
            "chosen": self.chosen,
            "frontier": list(self.rows),
            "limits": list(self.limits),
            "segment": self.segment,
            "parts": None if self.parts is None else self.parts.report,
            "out": None if self.out is None else str(self.out),
        }

    def __repr__(self):
        c = self.chosen
        units = ""
        if self.segment is not None:
            s = self.segment["chosen"]
            units = f", {s['n_units']} units of ±{s['unit_workspace_deg']:.4g}°"
        from reflector_opt.optimiser._size import judged_in_use

        worst = c.get("worst_case_deg")
        figure = "" if worst is None else f"in-use worst case {worst:.4f}°"
        if not judged_in_use(c):
            figure = f"objective {c['objective_deg']:.4f}°" + (figure and f", {figure}")
        return (
            f"SmallestRun: {c['part']} on {c['bearing']} at {c['unit_diameter_mm']:g} mm, "
            f"{figure} (white-noise floor {c['white_noise_deg']:.4f}°){units} "
            f"({len(self.rows)} frontier points, {self.out})"
        )


def _study(options):
    """The frontier's settings, the parts and the executor factory, checked before any work."""
    from reflector_opt.design._bearings import shipped_bearings
    from reflector_opt.model._catalogue import resolve_parts
    from reflector_opt.optimiser._search import check_search_work
    from reflector_opt.optimiser._size import SizeStudy, choose_bearing
    from reflector_opt.util._pools import executor_factory

    if options.resolution_mm > options.step_mm:  # each alone is checked by its declaration
        raise InputError("resolution_mm: must not exceed step_mm")
    keys = ("config", "seed", "workers", "conditions", "objective")  # in-use: in conditions
    prepared = prepare(OptimiseOptions(**{k: getattr(options, k) for k in keys}))
    problem, budget = prepared.config.problem, prepared.config.budget
    if problem.mechanics.joint is not None:
        raise InputError(
            "mechanics.joint: smallest sizes the unit on the catalogue's bearings, each point "
            "its own; a described joint is for optimise, evaluate and export"
        )
    bearings = shipped_bearings()
    problem = _unit_problem(problem, options, bearings)
    check_search_work(problem, budget, options.starts)  # the unit's workspace, as optimise's
    choose_bearing(bearings, problem.workspace, options.largest_mm)  # the bearing fits
    parts = resolve_parts(options.sensor)
    study = SizeStudy(
        problem,
        bearings,
        largest_mm=float(options.largest_mm),
        step_mm=float(options.step_mm),
        resolution_mm=float(options.resolution_mm),
        target_deg=float(options.target_deg),
        seed=prepared.seed,
        budget=budget,
        starts=options.starts,
        reported_in=prepared.conditions if problem.conditions is None else None,
    )
    factory = None if options.scheduler is None else executor_factory(options.scheduler, 1)
    return study, parts, factory


def _unit_problem(problem, options, bearings):
    """The problem with the unit's workspace — ±W, the segment's share with the fewest
    units, or the config's — refused in one line if no catalogue bearing permits it."""
    from reflector_opt.design import Workspace
    from reflector_opt.optimiser._segment_choice import (
        fewest_units,
        segment_mechanics,
        unit_workspace,
    )

    step = problem.workspace.step_deg
    if options.segment_range_deg is not None:
        if options.workspace_deg is not None:
            raise InputError(
                "--workspace-deg: not with --segment-range-deg (a unit's workspace is then "
                "its share of the segment's range)"
            )
        n = fewest_units(options.segment_range_deg, bearings)
        mechanics = segment_mechanics(problem.mechanics, n, options.link_mm)
        workspace = unit_workspace(options.segment_range_deg, n, step)
        return dataclasses.replace(problem, workspace=workspace, mechanics=mechanics)
    if options.link_mm is not None:
        raise InputError("--link-mm: only with --segment-range-deg")
    if options.workspace_deg is not None:
        w = options.workspace_deg
        workspace = Workspace((-w, w), (-w, w), step)
        _check_tilt(workspace, bearings, from_config=False)  # before the problem's own check
        return dataclasses.replace(problem, workspace=workspace)
    _check_tilt(problem.workspace, bearings, from_config=True)
    return problem


def _check_tilt(workspace, bearings, from_config):
    """Refuse a workspace beyond every bearing's mechanical stop, naming the largest it may
    be."""
    from reflector_opt.design._bearings import square_workspace_deg, workspace_tilt_deg

    tilt = workspace_tilt_deg(workspace.pitch_deg, workspace.roll_deg)
    best = max(bearings, key=lambda b: b.stop_deg)
    if tilt <= best.stop_deg + 1e-9:
        return
    largest = math.floor(10 * square_workspace_deg(best.stop_deg)) / 10
    whose = "the config's workspace" if from_config else "the workspace"
    raise InputError(
        f"--workspace-deg: {whose}, pitch {list(workspace.pitch_deg)}° and roll "
        f"{list(workspace.roll_deg)}°, tilts the unit by up to {tilt:.1f}° at the corner, "
        f"beyond the {best.stop_deg:.1f}° mechanical stop of the bearing that tilts most "
        f"({best.name}); give "
        f"--workspace-deg {largest:g} or less, or a segment's range (--segment-range-deg)"
    )


def _csv(rows, columns):
    """Rows as CSV text with these columns (an absent or None entry empty)."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, columns, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    writer.writerows({k: ("" if r.get(k) is None else r.get(k)) for k in columns} for r in rows)
    return buffer.getvalue()


def _write(work, design, rows, segment):
    """design.json, frontier.csv, frontier.png and, with a segment, segment.csv into
    ``work``; the names."""
    from reflector_opt.optimiser._segment_choice import SEGMENT_COLUMNS
    from reflector_opt.optimiser._size import FRONTIER_COLUMNS
    from reflector_opt.report._frontier import frontier_figure
    from reflector_opt.report._plots import save_figure
    from reflector_opt.util._fileio import write_text

    target_deg = design.predicted.size_frontier["target_deg"]
    design.save(work / "design.json")
    write_text(work / "frontier.csv", _csv(rows, FRONTIER_COLUMNS))
    save_figure(frontier_figure(rows, target_deg), work / "frontier.png")
    names = ["design.json", "frontier.csv", "frontier.png"]
    if segment is not None:
        write_text(work / "segment.csv", _csv(segment["choices"], SEGMENT_COLUMNS))
        names.append("segment.csv")
    return names


def _segment(study, parts, chosen, design, options, progress, executor):
    """The choices of units at the chosen size, the one chosen and its design: (record,
    design), or (None, design) without a segment's range."""
    from reflector_opt.optimiser._segment_choice import choose_segment, segment_choices

    if options.segment_range_deg is None:
        return None, design
    part = next(p for p in parts if p.name == chosen["part"])
    r, link = float(options.segment_range_deg), study.problem.mechanics.link_length_mm
    choices = segment_choices(
        study, part, chosen, design, r, link, options.segment_choices, progress, executor
    )
    row, errors, design = choose_segment(choices, study.target_deg)
    record = {"range_deg": r, "link_mm": link, "chosen": row, "errors": errors}
    return record | {"choices": [c[0] for c in choices]}, design


@takes(SmallestOptions)
def smallest(options, progress=None):
    """The smallest unit meeting an accuracy target, in memory: ``reflector-opt smallest``;
    :meth:`SmallestRun.write` writes it.

    Parameters
    ----------
    options : SmallestOptions
        As keyword arguments (below), or a SmallestOptions.
    progress : callable, optional
        ``progress(fraction, message)``.

    Returns
    -------
    SmallestRun

    Raises
    ------
    InputError
        Bad options (a target out of range or below the in-use floor no design goes below,
        :func:`~reflector_opt.optimiser._size.in_use_floor_deg`, an unknown objective or part, a
        workspace no catalogue bearing permits)
        before any work; a target no point reaches after the frontier, or parts of the chosen
        design that fail export's checks.
    """
    from reflector_opt.optimiser._size import size_frontier, size_limits, smallest_row
    from reflector_opt.workflow._export import export

    study, parts, factory = _study(options)
    progress = progress or no_progress
    share = PARTS_SHARE if options.segment_range_deg is None else 0.55
    points = size_frontier(study, parts, executor=factory, progress=scaled(progress, 0, share))
    rows = tuple(point[0] for point in points)
    chosen = smallest_row(rows, study.target_deg)
    design = next(p[2] for p in points if p[0] is chosen)
    segment_progress = scaled(progress, share, PARTS_SHARE)
    segment, design = _segment(study, parts, chosen, design, options, segment_progress, factory)
    record = {"target_deg": study.target_deg, "objective": options.objective, "chosen": chosen}
    record["conditions"] = (study.problem.conditions or study.reported_in).to_dict()
    record["frontier"] = list(rows)
    extra = {} if segment is None else {"segment_choice": segment}
    design = design.replace(predicted=design.predicted.replace(size_frontier=record, **extra))
    exported = export(design, progress=scaled(progress, PARTS_SHARE, 1.0))
    return SmallestRun(chosen, design, rows, segment, exported, tuple(size_limits(rows)))
