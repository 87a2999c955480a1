"""The segment: how many units cover a range, each with what workspace, and the tip error
predicted with built units for each choice.

A segment of N units bends to ±R in pitch and in roll when each unit turns ±R/N about each
axis: rotations about one axis add, so the paper's validation motions (pure pitch, pure
roll, the angle shared equally; :mod:`reflector_opt.calibration._segment`) reach ±R at the
tip exactly, and a unit's square workspace ±R/N × ±R/N holds any mix of the two. The
bearing bounds N from below: a square ±w × ±w asks a tilt of arccos(cos² w) at its corner
(:func:`~reflector_opt.design._bearings.workspace_tilt_deg`), so the largest square a bearing
of tilt α permits is w = arccos(√cos α) (:func:`~reflector_opt.design._bearings.
square_workspace_deg`; 11.3° for the GE 4 E's 16°) and N ≥ ⌈R / w⌉ (:func:`fewest_units`).
For ±90°: 8 units of ±11.25° on the GE 4 E.

More units than the fewest shrink each unit's workspace (its optimum's objective falls) but
add a unit's error more times and lengthen the segment (N × the link). Each choice is
judged by the error of the tip it predicts (:func:`tip_errors`): N units drawn from the
tolerance model and built with exact optics (:func:`~reflector_opt.tolerance._builtunit.
build_unit`), each calibrated with the recommended form on the recommended plan
(:data:`~reflector_opt.tolerance._prediction.RECOMMENDED_PLAN`), the segment swept through
±R in pitch and in roll, and through the paper's ±60° to set beside its Table I.
"""

import dataclasses
import functools
import math
import time

import numpy as np

from reflector_opt.calibration._segment import AXES, PAPER_AMPLITUDE_DEG, PAPER_TABLE_I
from reflector_opt.design._bearings import square_workspace_deg
from reflector_opt.design._components import Workspace
from reflector_opt.optimiser._size import judged_deg
from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import MAX_SEGMENT_UNITS

#: The columns of ``segment.csv`` (:func:`segment_choices`' rows): the tip errors over ±R
#: with the recommended calibration, degrees and mm.
SEGMENT_COLUMNS = (
    "n_units",
    "unit_workspace_deg",
    "segment_length_mm",
    "part",
    "unit_diameter_mm",
    "bearing",
    "status",
    "objective_deg",
    "worst_case_deg",
    "white_noise_deg",
    "pitch_rms_deg",
    "pitch_max_deg",
    "roll_rms_deg",
    "roll_max_deg",
    "orientation_rms_deg",
    "orientation_max_deg",
    "position_rms_mm",
    "position_max_mm",
    "reason",
    "seconds",
)

#: Validation poses per built unit (its own calibration's RMS, beside the segment's).
N_VALIDATION = 2000


def fewest_units(range_deg, bearings):
    """The fewest units that reach ±R at the tip, on the bearing that tilts most.

    N = ⌈R / w⌉ with w the largest square workspace the bearing permits (module notes).

    Parameters
    ----------
    range_deg : float
        The tip's range ±R in pitch and in roll, degrees, in (0, 90].
    bearings : sequence of reflector_opt.design._bearings.Bearing

    Returns
    -------
    int
        Raises :class:`~reflector_opt.util._errors.InputError` for a range outside (0, 90]
        (a tip pitch beyond 90° reads back as a smaller one, R = Rx·Ry·Rz) or one needing
        more than the segment's most units.
    """
    r = range_deg
    if isinstance(r, bool) or not isinstance(r, int | float) or not math.isfinite(r):
        raise InputError(f"--segment-range-deg: expected a finite number of degrees, got {r!r}")
    if not 0 < r <= 90:
        raise InputError(
            f"--segment-range-deg: {r:g}° is outside (0, 90]: no number of units gives a tip "
            "pitch beyond ±90° (it reads back as a smaller pitch with roll and twist of 180°)"
        )
    best = max(bearings, key=lambda b: b.tilt_deg)
    n = math.ceil(r / square_workspace_deg(best.tilt_deg) - 1e-9)
    if n > MAX_SEGMENT_UNITS:
        raise InputError(f"--segment-range-deg: {r:g}° needs {n} units, over {MAX_SEGMENT_UNITS}")
    return n


def unit_workspace(range_deg, n_units, step_deg):
    """A unit's share of the segment's range: ±R/N in pitch and in roll.

    Parameters
    ----------
    range_deg : float
        The tip's range ±R, degrees.
    n_units : int
    step_deg : float
        The workspace grid's step, degrees.

    Returns
    -------
    reflector_opt.design._components.Workspace
    """
    w = float(range_deg) / int(n_units)
    return Workspace((-w, w), (-w, w), step_deg)


def segment_mechanics(mechanics, n_units, link_mm):
    """The mechanics of a segment of ``n_units`` units ``link_mm`` apart.

    Parameters
    ----------
    mechanics : reflector_opt.design._components.Mechanics
    n_units : int
    link_mm : float or None
        Distance between consecutive rotation centres, mm (None keeps the mechanics'); at
        least the unit's height.

    Returns
    -------
    Mechanics
    """
    link = mechanics.link_length_mm if link_mm is None else link_mm
    if isinstance(link, bool) or not isinstance(link, int | float) or not math.isfinite(link):
        raise InputError(f"--link-mm: expected a finite length in mm, got {link!r}")
    if link < mechanics.unit_height_mm:
        raise InputError(
            f"--link-mm: {link:g} mm is less than the unit's height, "
            f"{mechanics.unit_height_mm:g} mm: the units would overlap"
        )
    return dataclasses.replace(mechanics, n_units=int(n_units), link_length_mm=float(link))


def tip_errors(design, range_deg, *, seed=0):
    """The segment's tip errors predicted with built units and their calibration.

    Builds ``design.mechanics.n_units`` units, calibrates each with the recommended form on
    the recommended plan and sweeps the segment of them (each unit estimated by its own fit)
    through ±``range_deg`` and through the paper's ±60° in pitch and in roll
    (:func:`~reflector_opt.calibration._segment.simulate_segment`).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        Its workspace must hold ±range/N about zero in pitch and roll.
    range_deg : float
        The segment's range, degrees.
    seed : int
        Seed of the units' draws, their calibration and the noise of the motions.

    Returns
    -------
    dict
        JSON-ready: ``range`` and ``paper_motion``, each ``{pitch, roll}`` with
        ``amplitude_deg`` and the predicted Table-I figures
        (:meth:`~reflector_opt.calibration._segment.SegmentErrors.summary`: ``rms_deg``,
        ``max_deg`` of the moved tip angle, ``orientation_*_deg``, ``position_*_mm``);
        ``paper_motion`` also the paper's measured ``paper`` figures; ``unit_rms_deg``: each
        unit's own calibration RMS (pitch, roll) over its workspace.
    """
    from reflector_opt.calibration._segment import simulate_segment

    pairs, units = _calibrated_units(design, seed)
    out = {"range": {}, "paper_motion": {}, "unit_rms_deg": units}
    for axis in AXES:
        for key, amplitude in (("range", range_deg), ("paper_motion", PAPER_AMPLITUDE_DEG)):
            amplitude = min(float(amplitude), float(range_deg))
            errors = simulate_segment(
                design, None, axis, amplitude_deg=amplitude, seed=seed, units=pairs
            )
            out[key][axis] = {"amplitude_deg": amplitude, "predicted": errors.summary()}
        out["paper_motion"][axis]["paper"] = dict(PAPER_TABLE_I[axis])
    return out


def _calibrated_units(design, seed):
    """(recorder, fitted model) of each built unit, and each unit's validation RMS."""
    from reflector_opt.calibration._plans import make_plan
    from reflector_opt.calibration._selection import AutoModel
    from reflector_opt.calibration._simulation import assess
    from reflector_opt.tolerance._builtunit import build_unit, built_unit_protocol
    from reflector_opt.tolerance._prediction import RECOMMENDED_PLAN

    plan = make_plan(design.workspace, RECOMMENDED_PLAN["pattern"], RECOMMENDED_PLAN["n_poses"])
    pairs, rms = [], []
    for index in range(design.mechanics.n_units):
        unit = build_unit(design, index, seed=seed)
        protocol = built_unit_protocol(unit, plan, n_validation=N_VALIDATION, seed=seed)
        fit = assess(AutoModel(seed=seed), protocol)

        def recorder(poses, rng, unit=unit):
            return unit.record(poses, rng, 0.0).volts

        pairs.append((recorder, fit.model.selected_))
        rms.append([float(v) for v in fit.total.rms_deg])
    return pairs, rms


def _choice_row(design, range_deg, seed, row):
    """One choice's row: the frontier row's unit with the tip errors over ±R."""
    t0 = time.perf_counter()
    n = design.mechanics.n_units
    errors = tip_errors(design, range_deg, seed=seed)
    out = {
        "n_units": n,
        "unit_workspace_deg": float(design.workspace.pitch_deg[1]),
        "segment_length_mm": n * design.mechanics.link_length_mm,
        **{k: row[k] for k in ("part", "unit_diameter_mm", "bearing")},
        "status": "feasible",
        **{k: row.get(k) for k in ("objective", "objective_deg", "worst_case_deg")},
        "white_noise_deg": row.get("white_noise_deg"),
    }
    predicted = [errors["range"][axis]["predicted"] for axis in AXES]
    for axis, summary in zip(AXES, predicted, strict=True):
        out[f"{axis}_rms_deg"], out[f"{axis}_max_deg"] = summary["rms_deg"], summary["max_deg"]
    for key in ("orientation_rms_deg", "position_rms_mm"):
        out[key] = float(np.sqrt(np.mean([p[key] ** 2 for p in predicted])))
    for key in ("orientation_max_deg", "position_max_mm"):
        out[key] = max(p[key] for p in predicted)
    out["seconds"] = round(time.perf_counter() - t0 + row.get("seconds", 0.0), 2)
    return out, errors


def segment_choices(
    study, part, row, design, range_deg, link_mm, count=3, progress=None, executor=None
):
    """Each choice of units from the fewest up: its unit, workspace and predicted tip errors.

    The first choice is the frontier's point (``row``, ``design``, optimised for ±R/N with
    the fewest units N); each further one, N + 1 … N + count − 1 units, is optimised afresh
    at the same part and diameter for its smaller workspace
    (:func:`~reflector_opt.optimiser._size.frontier_point`). Each choice is one task of
    ``executor``, as the frontier's parts are (:func:`~reflector_opt.optimiser._size.
    size_frontier`): the same choices wherever they run.

    Parameters
    ----------
    study : reflector_opt.optimiser._size.SizeStudy
        The frontier's study (its workspace is the fewest units' share).
    part : reflector_opt.model._catalogue.CataloguePart
    row : dict
        The chosen frontier row.
    design : reflector_opt.design._design.Design
        Its design.
    range_deg, link_mm : float
        The segment's range, degrees, and link, mm.
    count : int
        Choices to judge.
    progress : callable, optional
        ``progress(fraction, message)`` as each choice ends.
    executor : callable, optional
        Executor factory (:mod:`reflector_opt.util._pools`), e.g. a Dask cluster's; default
        the study budget's workers as local processes.

    Returns
    -------
    list of (dict, dict or None, Design or None)
        Per choice: its row (:data:`SEGMENT_COLUMNS`), the :func:`tip_errors` and the design
        (None where no design fits that workspace at this size).
    """
    from reflector_opt.optimiser._studies import in_tasks

    fewest = fewest_units(range_deg, study.bearings)
    args = (study, part, row, design, float(range_deg), link_mm, fewest)
    task = functools.partial(_one_choice, args)
    return in_tasks(task, range(int(count)), study.budget, executor, progress)


def _one_choice(args, k, budget):
    """The (row, errors, design) of the choice with ``k`` units more than the fewest, its
    search under ``budget``."""
    from reflector_opt.optimiser._size import frontier_point

    study, part, row, design, range_deg, link_mm, fewest = args
    study, n = dataclasses.replace(study, budget=budget), fewest + k
    if k > 0:
        workspace = unit_workspace(range_deg, n, study.problem.workspace.step_deg)
        mechanics = segment_mechanics(study.problem.mechanics, n, link_mm)
        problem = dataclasses.replace(study.problem, workspace=workspace, mechanics=mechanics)
        row, _, result = frontier_point(
            dataclasses.replace(study, problem=problem), part, row["unit_diameter_mm"]
        )
        design = None if result is None else result.design
    if design is None:
        return {"n_units": n, **_unfitted(row, range_deg / n)}, None, None
    design = design.replace(mechanics=segment_mechanics(design.mechanics, n, link_mm))
    choice, errors = _choice_row(design, range_deg, study.seed, row)
    return choice, errors, design


def _unfitted(row, workspace_deg):
    keys = ("part", "unit_diameter_mm", "bearing", "status", "reason", "seconds")
    return {"unit_workspace_deg": workspace_deg, **{k: row.get(k) for k in keys}}


def choose_segment(choices, target_deg=None):
    """The fewest units no other choice beats at the tip in both orientation and position.

    More units shrink each unit's workspace but lengthen the segment and add a unit's error
    more times; a larger count is taken only when another choice with fewer units is beaten
    in both the tip-orientation and the tip-position RMS error. Of the choices whose unit
    meets the target, if any.

    Parameters
    ----------
    choices : sequence of (dict, dict or None, Design or None)
        :func:`segment_choices`' output.
    target_deg : float, optional
        The unit's figure to meet, degrees (:func:`~reflector_opt.optimiser._size.judged_deg`:
        its in-use worst case where it has one).

    Returns
    -------
    tuple
        The chosen ``(row, errors, design)``; InputError when no choice has a design.
    """
    fitted = [c for c in choices if c[2] is not None]
    if not fitted:
        raise InputError("--segment-range-deg: no choice of units has a design at this size")
    meeting = [c for c in fitted if target_deg is None or judged_deg(c[0]) <= target_deg]
    pool = meeting or fitted
    keys = ("orientation_rms_deg", "position_rms_mm")

    def beaten(c):
        return any(all(o[0][k] < c[0][k] for k in keys) for o in pool)

    return min((c for c in pool if not beaten(c)), key=lambda c: c[0]["n_units"])
