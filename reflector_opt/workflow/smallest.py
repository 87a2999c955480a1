"""The smallest unit for an accuracy target, as ``reflector-opt smallest`` makes it: the
size–accuracy frontier of each sensor part over the catalogue's bearings
(:mod:`reflector_opt.optimise.size`), the smallest unit meeting the target, and its design,
written into one output folder with the frontier as a table and a figure."""

from __future__ import annotations

import csv
import dataclasses
import io
import math
from dataclasses import dataclass
from pathlib import Path

from reflector_opt.util.errors import InputError
from reflector_opt.util.progress import no_progress

__all__ = ["SmallestOptions", "SmallestRun", "smallest_run"]

#: The command recorded in an output folder's manifest when the library wrote it.
LIBRARY_COMMAND = ("reflector_opt", "smallest")


@dataclass(frozen=True)
class SmallestOptions:
    """The options of ``reflector-opt smallest``.

    Attributes
    ----------
    target_deg : float
        The objective to meet (``--target-deg``), the quantity ``optimise`` reports: the
        worst-case 1σ resolution with the isotropy weight, or in ``conditions`` the
        worst-case total error, degrees.
    sensor : str
        ``auto``, part names or ``PARTS.toml`` files (``--sensor``).
    conditions, config, seed, workers, scheduler
        As for ``optimise`` (:class:`~reflector_opt.workflow.options.OptimiseOptions`).
    workspace_deg : float or None
        Pitch and roll range ±this, degrees (``--workspace-deg``); None for the config's.
    largest_mm, step_mm, resolution_mm : float
        The frontier's first diameter, its step down and the resolution of its edges, mm.
    """

    target_deg: float
    sensor: str = "auto"
    conditions: object = None
    config: object = None
    seed: int | None = None
    workers: int | None = None
    scheduler: str | None = None
    workspace_deg: float | None = None
    largest_mm: float = 22.0
    step_mm: float = 2.0
    resolution_mm: float = 0.5


@dataclass(frozen=True)
class SmallestRun:
    """What :func:`smallest_run` found and wrote.

    Attributes
    ----------
    chosen : dict
        The frontier row of the smallest unit meeting the target.
    design : reflector_opt.design.design.Design
        Its design; ``predicted["size_frontier"]`` holds the target, the chosen row and the
        frontier.
    rows : tuple of dict
        The frontier, part by part, largest diameter first.
    out : pathlib.Path
    files : list of pathlib.Path
    """

    chosen: dict
    design: object
    rows: tuple
    out: Path
    files: list

    def to_dict(self):
        """JSON-ready summary (the command's ``--json``)."""
        return {"chosen": self.chosen, "frontier": list(self.rows), "out": str(self.out)}

    def __repr__(self):
        c = self.chosen
        return (
            f"SmallestRun: {c['part']} on {c['bearing']} at {c['unit_diameter_mm']:g} mm, "
            f"objective {c['objective_deg']:.4f}° ({len(self.rows)} frontier points, {self.out})"
        )


def _check_options(options):
    """Refuse a target or a size that cannot be used, before any work."""
    target = options.target_deg
    if isinstance(target, bool) or not isinstance(target, int | float) or not math.isfinite(target):
        raise InputError(f"--target-deg: expected a finite number of degrees, got {target!r}")
    if not 0 < target < 90:
        raise InputError(f"--target-deg: must lie in (0, 90) degrees, got {target:g}")
    for name in ("largest_mm", "step_mm", "resolution_mm"):
        value = getattr(options, name)
        if not (isinstance(value, int | float) and math.isfinite(value) and 0 < value <= 1000):
            raise InputError(f"{name}: expected a length in (0, 1000] mm, got {value!r}")
    if options.resolution_mm > options.step_mm:
        raise InputError("resolution_mm: must not exceed step_mm")


def _study(options):
    """The frontier's settings, the parts and the executor factory, checked before any work."""
    from reflector_opt.design import Workspace
    from reflector_opt.design.bearings import shipped_bearings
    from reflector_opt.model.catalogue import resolve_parts
    from reflector_opt.optimise.size import SizeStudy, choose_bearing
    from reflector_opt.workflow.optimise import executor_factory
    from reflector_opt.workflow.options import OptimiseOptions, prepare

    _check_options(options)
    keys = ("config", "seed", "workers", "conditions")
    prepared = prepare(OptimiseOptions(**{k: getattr(options, k) for k in keys}))
    problem, budget = prepared.config.problem, prepared.config.budget
    if options.workspace_deg is not None:
        w = options.workspace_deg
        if not (isinstance(w, int | float) and math.isfinite(w) and 0 < w < 90):
            raise InputError(f"--workspace-deg: must lie in (0, 90) degrees, got {w!r}")
        step = problem.workspace.step_deg
        problem = dataclasses.replace(problem, workspace=Workspace((-w, w), (-w, w), step))
    bearings = shipped_bearings()
    choose_bearing(bearings, problem.workspace, options.largest_mm)  # the tilt, before work
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
    )
    factory = None if options.scheduler is None else executor_factory(options.scheduler, 1)
    return study, parts, factory


def frontier_csv(rows):
    """The frontier as CSV text, the columns of ``FRONTIER_COLUMNS``.

    Parameters
    ----------
    rows : sequence of dict

    Returns
    -------
    str
    """
    from reflector_opt.optimise.size import FRONTIER_COLUMNS

    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, FRONTIER_COLUMNS, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    writer.writerows(
        {k: ("" if r.get(k) is None else r.get(k)) for k in FRONTIER_COLUMNS} for r in rows
    )
    return buffer.getvalue()


def _write(work, design, rows, target_deg):
    """design.json, frontier.csv and frontier.png into ``work``; their names."""
    from reflector_opt.report.frontier import frontier_figure
    from reflector_opt.report.plots import save_figure
    from reflector_opt.util.fileio import write_text

    design.save(work / "design.json")
    write_text(work / "frontier.csv", frontier_csv(rows))
    save_figure(frontier_figure(rows, target_deg), work / "frontier.png")
    return ["design.json", "frontier.csv", "frontier.png"]


def smallest_run(options, *, out, progress=None, command=LIBRARY_COMMAND):
    """The smallest unit meeting an accuracy target: ``reflector-opt smallest``.

    Parameters
    ----------
    options : SmallestOptions
    out : str or pathlib.Path
        The output folder: ``design.json`` (the smallest unit meeting the target, its part and
        bearing named, the frontier in ``predicted["size_frontier"]``), ``frontier.csv`` and
        ``frontier.png``; written whole or not at all.
    progress : callable, optional
        ``progress(fraction, message)``.
    command : sequence of str, optional
        The command line recorded in the folder's manifest.

    Returns
    -------
    SmallestRun

    Raises
    ------
    InputError
        Bad options (a target out of range, an unknown part, a workspace no catalogue bearing
        permits) before any work; a target no point reaches (below the noise floor of the
        parts in this workspace) after the frontier, with nothing written.
    """
    from reflector_opt.optimise.size import size_frontier, smallest_row
    from reflector_opt.util.atomic import atomic_folder

    study, parts, factory = _study(options)
    points = size_frontier(study, parts, executor=factory, progress=progress or no_progress)
    rows = tuple(point[0] for point in points)
    chosen = smallest_row(rows, study.target_deg)
    design = next(p[2] for p in points if p[0] is chosen)
    record = {"target_deg": study.target_deg, "chosen": chosen, "frontier": list(rows)}
    design = design.replace(predicted={**design.predicted, "size_frontier": record})
    with atomic_folder(out, command) as work:
        names = _write(work, design, rows, study.target_deg)
    out = Path(out)
    return SmallestRun(chosen, design, rows, out, [out / n for n in names])
