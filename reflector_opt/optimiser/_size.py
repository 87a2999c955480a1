"""Size as a design variable: the size–accuracy frontier of each sensor part.

For each part, :func:`part_frontier` optimises the unit at a sequence of diameters, from
the largest (the paper's 22 mm) down in steps until no design fits, then halves the last
interval down to the resolution (0.5 mm): the smallest feasible diameter, and, with a target,
the smallest meeting it. Each point is one single-envelope optimisation
(:func:`~reflector_opt.optimiser._search.optimise`) under the problem of :func:`size_problem`
— the part (:func:`~reflector_opt.optimiser._sensor_choice.part_problem`), the diameter and a
catalogue bearing, named in the mechanics (``mechanics.bearing``), whose widths and ball
diameter, with the tendon circle inside the rim, the layout of the parts takes from the design
(:func:`reflector_opt.design._parts.design_parameters`) — so every constraint the optimiser
proves holds at every point, the point's ``design.json`` alone exports and reports its parts,
and one ``optimise`` run with that envelope (:func:`point_config`) gives the same design.
Each point is the best of ``starts`` (3) independent searches from seeds spawned from the
study's (``numpy.random.SeedSequence.spawn``), each polished, the best verified: at the edge
of the envelope the objective has basins far apart (for the VCNT2020 at 20 mm, 0.0685° and
0.0736°, half the seeds in each), which one search finds by chance. Each search starts
cold: the optimum of the larger neighbour placed in the initial population
(``optimise(initial=…)``, same budget) was measured against cold searches and kept out
(docs/smallest.md, "Cost").

Monotone by construction. A larger envelope holds every design of a smaller one: after the
searches, each point also judges the design of its nearest smaller feasible point under its
own problem (every constraint, the printed walls too) and keeps it if it is better
(``carried_from_mm`` names the size it came from, ``searched_deg`` keeps the point's own
search). So the objective never rises as the unit grows, whatever the search budget; this
is the work neighbouring sizes share, one evaluation a point.

The bearing. The shell's inner radius (bearing OD/2 + clearance) enters no optics, only the
walls, so a smaller bearing never gives a worse optimum: each point is searched with the
smallest-OD bearing whose tilt covers the workspace, and the row also names the largest
catalogue bearing the same design still clears (``largest_bearing``: the design's
variables under that bearing's problem, every constraint met), the one to build with.

In use. With operating conditions (``problem.conditions``: ``smallest``'s default, the
default conditions where none are given) each point's search minimises its in-use worst case
and the target is judged by it, ``worst_case_deg`` (:attr:`ErrorBudget.worst_case_deg
<reflector_opt.analysis._budget.ErrorBudget.worst_case_deg>`); the white-noise floor,
``white_noise_deg`` (the worst 1σ resolution), is recorded beside it. Without conditions
(``--objective resolution``) the target is judged by the objective, as before. Some of the
in-use error no design removes: the angle reference's zero and its lag
(:func:`in_use_floor_deg`); a target below it is refused before any search.

The binding constraint of a point is the one with the smallest margin relative to its scale
at the optimum (``binding``, ``binding_margin`` in its unit); a size no design fits names
what failed (``reason``). Parts run as independent tasks on local processes or a Dask
cluster (:mod:`reflector_opt.util._pools`), the sizes of one part in order in one task: the
same frontier wherever they run.
"""

import dataclasses
import functools
import math
import re
import time
from dataclasses import dataclass

from reflector_opt.design._bearings import workspace_tilt_deg
from reflector_opt.design._parts import FROM_DESIGN
from reflector_opt.optimiser._search import SearchBudget
from reflector_opt.optimiser._sensor_choice import part_problem
from reflector_opt.optimiser._studies import in_tasks, optimise_variants
from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import MAX_STARTS, check_count
from reflector_opt.util._pools import in_this_process, local_processes, reused

#: The columns of ``frontier.csv`` (:func:`size_frontier`'s rows, ``values`` left out).
FRONTIER_COLUMNS = (
    "part",
    "unit_diameter_mm",
    "status",
    "objective_deg",
    "worst_case_deg",
    "white_noise_deg",
    "bearing",
    "largest_bearing",
    "binding",
    "binding_margin",
    "binding_unit",
    "reason",
    "searched_deg",
    "carried_from_mm",
    "seconds",
)


@dataclass(frozen=True)
class SizeStudy:
    """What a frontier is traced under.

    Attributes
    ----------
    problem : reflector_opt.optimiser._problem.Problem
        Workspace, noise, surface, limits and conditions; its sensor, mechanics diameter and
        bearing and bounds are set per point. Its CAD parameters leave the bearing's widths
        and the tendon circle to each point's design (:data:`~reflector_opt.design._parts.
        FROM_DESIGN`; one given is refused: it would hold at every size and bearing).
    bearings : tuple of reflector_opt.design._bearings.Bearing
        The bearings a point may use.
    largest_mm, step_mm, resolution_mm : float
        First diameter, the step down, and the resolution of the edges, mm (22, 2, 0.5).
    target_deg : float or None
        The figure to meet, degrees (:func:`judged_deg`): in the problem's conditions the
        in-use worst case, without them the objective; its edge is refined too. One below
        :func:`in_use_floor_deg` is refused.
    seed : int
    budget : reflector_opt.optimiser._search.SearchBudget, optional
        The default :class:`~reflector_opt.optimiser._search.SearchBudget` when None.
    starts : int
        Independent searches of each point, from the seeds
        :func:`~reflector_opt.optimiser._search.start_seeds` derives from ``seed``
        (``numpy.random.SeedSequence.spawn``), each polished, the best verified
        (``optimise(starts=…)``; module notes).
    reported_in : reflector_opt.design._conditions.Conditions, optional
        Without the problem's conditions (``--objective resolution``), the conditions each
        point is judged in afterwards: its ``worst_case_deg`` in them, reported beside the
        objective its target judges (``objective`` ``"resolution"``, :func:`judged_deg`).
    """

    problem: object
    bearings: tuple
    largest_mm: float = 22.0
    step_mm: float = 2.0
    resolution_mm: float = 0.5
    target_deg: float | None = None
    seed: int = 0
    budget: object = None
    starts: int = 3
    reported_in: object = None

    def __post_init__(self):
        check_count(self.starts, "starts", 1, MAX_STARTS)
        if self.budget is None:
            object.__setattr__(self, "budget", SearchBudget())
        given = [k for k in FROM_DESIGN if getattr(self.problem.cad, k) is not None]
        if given:
            raise InputError(
                f"cad.{given[0]}: the frontier lays each size out with its own bearing and "
                "diameter; leave it out of the [cad] table"
            )
        conditions = self.problem.conditions
        if self.target_deg is not None and conditions is not None:
            floor = in_use_floor_deg(conditions)
            if self.target_deg < floor:
                raise InputError(_floor_message(self.target_deg, floor, conditions))


def in_use_floor_deg(conditions):
    """The in-use worst case no design goes below: the angle reference's zero and lag, degrees.

    The budget's ``reference`` source holds every sign of the zero offset z
    (:meth:`~reflector_opt.design._conditions.Conditions.reference_zero`) with the axes' twist,
    and its ``latency`` source the lag ±ω·τ of every pose (:mod:`~reflector_opt.analysis.
    budget`): at each pose and angle the sign of z that adds to the twist gives at least
    abs(z), so the total there is at least ``sqrt(z² + (ω·τ)²)``, whatever the design.

    Parameters
    ----------
    conditions : reflector_opt.design._conditions.Conditions

    Returns
    -------
    float
        The larger over pitch and roll, degrees.
    """
    lag = 1e-3 * conditions.angular_speed_deg_s * conditions.reference_latency_ms
    return max(math.hypot(z, lag) for z in conditions.reference_zero())


def _floor_message(target_deg, floor_deg, conditions):
    """The one-line answer to a target below :func:`in_use_floor_deg`."""
    figure = conditions.reference_figure()
    whose = (
        "the stated reference_zero_deg"
        if figure is None
        else f"{conditions.angle_reference}'s {figure['value']:g}° class ({figure['kind']})"
    )
    return (
        f"--target-deg: {target_deg:g}° is below the in-use floor of {floor_deg:.4g}° that no "
        f"design goes below in these conditions: the angle reference's zero ({whose}) and its "
        "lag; a better reference lowers it — [conditions] angle_reference = "
        '"imu-lpms-b2" (0.5°) or "encoder", or a measured reference_zero_deg — or give '
        "--objective resolution to target the white-noise resolution"
    )


def judged_in_use(row):
    """Whether a target judges a frontier row by its in-use worst case: where its search
    minimised it (not ``objective`` ``"resolution"``) and it has one (``worst_case_deg``)."""
    return row.get("worst_case_deg") is not None and row.get("objective") != "resolution"


def judged_deg(row):
    """The figure a target judges a frontier row by: its in-use worst case
    (:func:`judged_in_use`), else its objective, degrees."""
    return row["worst_case_deg"] if judged_in_use(row) else row["objective_deg"]


def choose_bearing(bearings, workspace, diameter_mm):
    """The bearing a point is searched with: smallest OD whose mechanical stop covers the
    workspace (past its rated tilt, :func:`~reflector_opt.design._bearings.check_tilt` warns).

    Parameters
    ----------
    bearings : sequence of Bearing
    workspace : reflector_opt.design._components.Workspace
    diameter_mm : float
        The unit's diameter; the bearing's OD must be smaller.

    Returns
    -------
    Bearing
        Raises :class:`~reflector_opt.util._errors.InputError` saying why none fits.
    """
    tilt = workspace_tilt_deg(workspace.pitch_deg, workspace.roll_deg)
    tilted = [b for b in bearings if b.stop_deg >= tilt - 1e-9]
    if not tilted:
        best = max(bearings, key=lambda b: b.stop_deg)
        raise InputError(
            f"bearing: the workspace tilts the unit by up to {tilt:.1f}°; the most any "
            f"bearing permits is {best.stop_deg:.1f}° ({best.name}'s mechanical stop)"
        )
    fitting = [b for b in tilted if b.outer_diameter_mm < diameter_mm]
    if not fitting:
        small = min(tilted, key=lambda b: b.outer_diameter_mm)
        raise InputError(
            f"bearing: the smallest bearing, {small.name}, is {small.outer_diameter_mm:g} mm "
            f"across, not inside a {diameter_mm:g} mm unit"
        )
    return min(fitting, key=lambda b: (b.outer_diameter_mm, -b.bore_mm))


def size_problem(problem, part, diameter_mm, bearing):
    """The single-envelope problem of one frontier point.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
    part : reflector_opt.model._catalogue.CataloguePart
    diameter_mm : float
    bearing : str
        A catalogue bearing (its bore, OD and, in the CAD parameters, widths).

    Returns
    -------
    Problem
        With the default bounds of the part and envelope; the CAD parameters the problem's
        (the layout takes the bearing's widths and the tendon circle from the design). Raises
        InputError when no design within them can meet the settings.
    """
    mechanics = dataclasses.replace(
        problem.mechanics, unit_diameter_mm=float(diameter_mm), bearing=bearing
    )
    base = dataclasses.replace(problem, mechanics=mechanics, bounds={})
    return part_problem(base, part)


def point_config(study, row):
    """An optimiser config (TOML text) whose ``optimise --sensor PART --starts N`` run is
    this point (N the study's ``starts``, named in the config's first line).

    Parameters
    ----------
    study : SizeStudy
    row : dict
        A frontier row.

    Returns
    -------
    str
        ``[mechanics]`` with the diameter and bearing (whose widths the layout takes), the
        workspace and the search budget; the other settings are the defaults, as
        ``study.problem``'s should be for the run to reproduce the point.
    """
    problem, budget = study.problem, study.budget
    w = problem.workspace
    lines = [
        f"# reflector-opt optimise --config THIS --sensor {row['part']} --starts {study.starts}",
        "[mechanics]",
        f"unit_diameter_mm = {row['unit_diameter_mm']!r}",
        f'bearing = "{row["bearing"]}"',
        "[workspace]",
        f"pitch_deg = {list(w.pitch_deg)!r}",
        f"roll_deg = {list(w.roll_deg)!r}",
        f"step_deg = {w.step_deg!r}",
        "[search]",
        f"seed = {study.seed}",
    ]
    for key in ("workers", "popsize", "maxiter", "tol", "grid_step_deg", "polish_step_deg"):
        lines.append(f"{key} = {getattr(budget, key)!r}")
    lines.append(f"polish_maxiter = {budget.polish_maxiter}")
    return "\n".join(lines) + "\n"


def _binding(evaluation):
    """The constraint with the least margin relative to its scale: name, margin, unit (a
    count held at its limit of zero, such as ``axis_miss_fraction``, is not binding)."""
    real = [c for c in evaluation.constraints if not (c.value == c.limit == 0)]
    c = min(real, key=lambda c: c.margin / c.scale)
    return c.name, float(c.margin), c.unit


def _judge(study, part, diameter_mm, bearing, values):
    """The evaluation of the design of ``values`` under the point's problem with ``bearing``
    (every constraint, the printed walls too), or None if it fails any."""
    try:
        problem = size_problem(study.problem, part, diameter_mm, bearing)
        evaluation = problem.check_printed(problem.evaluate(values))
    except InputError:
        return None
    return evaluation if evaluation.feasible else None


def _largest_bearing(study, part, diameter_mm, values):
    """The largest-OD bearing under which the design of ``values`` meets every constraint."""
    tilt = workspace_tilt_deg(study.problem.workspace.pitch_deg, study.problem.workspace.roll_deg)
    for bearing in sorted(study.bearings, key=lambda b: -b.outer_diameter_mm):
        if bearing.stop_deg < tilt - 1e-9 or bearing.outer_diameter_mm >= diameter_mm:
            continue
        if _judge(study, part, diameter_mm, bearing.name, values) is not None:
            return bearing.name
    return None


def frontier_point(study, part, diameter_mm, executor=None):
    """One frontier point: the part optimised at one diameter (:func:`size_problem`), the
    best of the study's ``starts`` searches.

    Parameters
    ----------
    study : SizeStudy
    part : reflector_opt.model._catalogue.CataloguePart
    diameter_mm : float
    executor : callable, optional
        Executor factory of the starts (:mod:`reflector_opt.util._pools`); default each in
        this process, in turn. The result does not depend on where they run.

    Returns
    -------
    row : dict
        The columns of :data:`FRONTIER_COLUMNS`; ``status`` ``infeasible`` with the
        ``reason`` and what failed as ``binding`` when no design fits.
    values : dict or None
        The optimum's variables.
    result : reflector_opt.optimiser._result.OptimisationResult or None
    """

    row = {"part": part.name, "unit_diameter_mm": float(diameter_mm), "bearing": None}

    def vary(diameter):
        bearing = choose_bearing(study.bearings, study.problem.workspace, diameter)
        row["bearing"] = bearing.name
        return size_problem(study.problem, part, diameter, bearing.name)

    t0 = time.perf_counter()
    (point,) = optimise_variants(
        [(f"{part.name} at {diameter_mm:g} mm", float(diameter_mm))],
        vary,
        seed=study.seed,
        budget=dataclasses.replace(study.budget, workers=1),
        starts=study.starts,
        figures=lambda result, _: _judged(study, part, diameter_mm, result.evaluation),
        executor=in_this_process() if executor is None else executor,
    )
    if point.error is None:
        row |= point.figures | {"searched_deg": point.figures["objective_deg"]}
    else:
        reason = point.reason
        row |= {"status": "infeasible", "reason": reason, "binding": _failed(reason, part.name)}
    return {**row, "seconds": round(time.perf_counter() - t0, 2)}, point.values, point.result


def _judged(study, part, diameter_mm, evaluation):
    """The row entries of a feasible evaluation: objective, in-use worst case (in the
    study's ``reported_in`` without the search's conditions; else None), white-noise floor,
    binding, largest bearing."""
    from reflector_opt.analysis._budget import error_budget

    name, margin, unit = _binding(evaluation)
    budget, m = evaluation.budget, evaluation.metrics
    objective = "resolution" if budget is None else "in-use"
    if budget is None and study.reported_in is not None:
        budget = error_budget(evaluation.design, study.reported_in)
    return {
        "status": "feasible",
        "objective": objective,
        "objective_deg": float(evaluation.objective),
        "worst_case_deg": None if budget is None else float(budget.worst_case_deg),
        "white_noise_deg": float(max(m.worst_pitch_deg, m.worst_roll_deg)),
        "largest_bearing": _largest_bearing(study, part, diameter_mm, evaluation.values),
        "binding": name,
        "binding_margin": margin,
        "binding_unit": unit,
        "reason": None,
    }


def _carry(study, part, found, diameter_mm):
    """Judge the nearest smaller feasible point's design under this point's problem and keep
    it if every constraint holds and its objective is lower (module notes)."""
    _, result, row = found[diameter_mm]
    smaller = [d for d in found if d < diameter_mm and found[d][0] is not None]
    if not smaller or row["bearing"] is None:
        return
    source = max(smaller)
    evaluation = _judge(study, part, diameter_mm, row["bearing"], found[source][0])
    if evaluation is None:
        return
    if row["status"] == "feasible" and evaluation.objective >= row["objective_deg"]:
        return
    base = found[source][1] if result is None else result
    carried = dataclasses.replace(base, evaluation=evaluation, design=None)
    carried = dataclasses.replace(
        carried, design=evaluation.design.replace(predicted=carried.predicted())
    )
    row |= _judged(study, part, diameter_mm, evaluation) | {"carried_from_mm": source}
    found[diameter_mm] = (dict(evaluation.values), carried, row)


def _monotone(study, part, found):
    """:func:`_carry` at every size, smallest first (a carried design carries on)."""
    for diameter in sorted(found):
        _carry(study, part, found, diameter)


def _failed(reason, part_name):
    """The name of what failed, from a one-line reason ("… grid: separation_sigma is …" →
    "separation_sigma", "NJL5901R-2 (…): wall: …" → "wall")."""
    text = reason
    if text.startswith(f"{part_name} ("):
        text = text.split("): ", 1)[-1]
    for marker in ("the closest: ", " grid: "):
        text = text.split(marker, 1)[-1]
    found = re.match(r"([A-Za-z][\w ]*?)(?= is | \(|:)", text)
    return found.group(1) if found else text[:40]


def _meets(row, target):
    ok = row["status"] == "feasible"
    return ok and (target is None or judged_deg(row) <= target)


def _refine(study, part, good, bad_mm, found, predicate, executor):
    """Halve the interval between a row meeting ``predicate`` and a smaller diameter that
    does not, on the resolution's grid."""
    step = study.resolution_mm
    while good["unit_diameter_mm"] - bad_mm > step + 1e-9:
        middle = 0.5 * (good["unit_diameter_mm"] + bad_mm)
        middle = bad_mm + step * max(1, round((middle - bad_mm) / step))
        row = _add(study, part, found, middle, executor)
        if predicate(row):
            good = row
        else:
            bad_mm = middle
    return good


def _add(study, part, found, diameter_mm, executor):
    """Search one size, store it in ``found`` (``{mm: (values, result, row)}``), carry the
    smaller neighbour's design into it if better (:func:`_carry`); its row."""
    row, values, result = frontier_point(study, part, diameter_mm, executor)
    found[diameter_mm] = (values, result, row)
    _carry(study, part, found, diameter_mm)
    return found[diameter_mm][2]


def part_frontier(study, part, progress=None, executor=None):
    """The frontier of one part: the coarse sizes down to the first that fails, and its edges.

    Parameters
    ----------
    study : SizeStudy
    part : reflector_opt.model._catalogue.CataloguePart
    progress : callable, optional
        ``progress(fraction, message)`` after each point (the fraction a guess).
    executor : callable, optional
        Executor factory of each point's starts (:func:`frontier_point`).

    Returns
    -------
    list of tuple
        ``(row, values, design)`` per point, largest diameter first; ``values`` and
        ``design`` None where no design fits. The objective never rises with the diameter
        (module notes).
    """
    found, diameter, last = {}, float(study.largest_mm), None
    while diameter > 0:
        row = _add(study, part, found, diameter, executor)  # nothing smaller to carry yet
        if progress is not None:
            progress(min(0.9, (study.largest_mm - diameter) / study.largest_mm), _said(row))
        if row["status"] != "feasible":
            break
        last, diameter = row, round(diameter - study.step_mm, 9)
    if last is not None:
        if diameter > 0:
            _refine(study, part, last, diameter, found, lambda r: _meets(r, None), executor)
        _monotone(study, part, found)
        _target_edge(study, part, found, executor)
    return [
        (row, values, None if result is None else result.design)
        for _, (values, result, row) in sorted(found.items(), reverse=True)
    ]


def _target_edge(study, part, found, executor):
    """Refine the smallest diameter meeting the target, if the target splits two sizes."""
    if study.target_deg is None:
        return
    rows = [v[2] for _, v in sorted(found.items(), reverse=True)]
    meeting = [r for r in rows if _meets(r, study.target_deg)]
    if not meeting:
        return
    good = min(meeting, key=lambda r: r["unit_diameter_mm"])
    edge = good["unit_diameter_mm"]
    smaller = [r["unit_diameter_mm"] for r in rows if r["unit_diameter_mm"] < edge]
    if smaller:
        meets = functools.partial(_meets, target=study.target_deg)
        _refine(study, part, good, max(smaller), found, meets, executor)


def _said(row):
    what = f"{judged_deg(row):.4f}°" if row["status"] == "feasible" else "no design fits"
    return f"{row['part']} at {row['unit_diameter_mm']:g} mm: {what}"


def _part_task(study, part, budget):
    """One task of :func:`size_frontier`: the frontier of a part under the task's budget."""
    return part_frontier(dataclasses.replace(study, budget=budget), part)


def size_frontier(study, parts, *, executor=None, progress=None):
    """The frontier of every part: one task per part.

    Parameters
    ----------
    study : SizeStudy
    parts : sequence of reflector_opt.model._catalogue.CataloguePart
    executor : callable, optional
        Executor factory (:mod:`reflector_opt.util._pools`), e.g. a Dask cluster's; default
        the budget's workers as local processes (one part alone runs here, its searches on
        the budget's workers).
    progress : callable, optional
        ``progress(fraction, message)``.

    Returns
    -------
    list of tuple
        ``(row, values, design)`` of every point, part by part, largest diameter first.
    """

    if len(parts) == 1 and executor is None:  # its points' starts on the local workers
        with reused(local_processes(study.budget.workers)) as starts:
            return part_frontier(study, parts[0], progress, starts)
    task = functools.partial(_part_task, study)
    frontiers = in_tasks(task, parts, study.budget, executor, progress)
    return [point for frontier in frontiers for point in frontier]


def smallest_row(rows, target_deg):
    """The smallest unit meeting the target: the least diameter, then the least figure
    (:func:`judged_deg`: in use where the rows have it).

    Parameters
    ----------
    rows : sequence of dict
    target_deg : float

    Returns
    -------
    dict
        Raises :class:`~reflector_opt.util._errors.InputError` naming the best figure the
        frontier reaches when no point meets the target.
    """
    meeting = [r for r in rows if _meets(r, target_deg)]
    if meeting:
        return min(meeting, key=lambda r: (r["unit_diameter_mm"], judged_deg(r)))
    feasible = [r for r in rows if r["status"] == "feasible"]
    if not feasible:
        raise InputError("no part fits any unit size: " + "; ".join(r["reason"] for r in rows))
    best = min(feasible, key=judged_deg)
    what = (
        "the white-noise floor of the catalogue's parts in this workspace"
        if not judged_in_use(best)
        else "the least in-use worst case in the conditions the searches found"
    )
    raise InputError(
        f"--target-deg: {target_deg:g}° is below what any part reaches: the best is "
        f"{judged_deg(best):.4g}° ({best['part']} at {best['unit_diameter_mm']:g} mm), {what}"
    )


def size_limits(rows):
    """Per part, the smallest diameter a design fits and what fails at the next size tried.

    Parameters
    ----------
    rows : sequence of dict
        Frontier rows (:func:`size_frontier`).

    Returns
    -------
    list of dict
        Per part, in the rows' order: ``part``, ``smallest_mm`` (None when no size fits),
        ``fails_at_mm`` (the largest size tried below it where no design fits; None when
        none was tried), its ``binding`` (what failed) and ``reason`` (the one line).
    """
    out = []
    for part in dict.fromkeys(r["part"] for r in rows):
        own = [r for r in rows if r["part"] == part]
        smallest = min([r["unit_diameter_mm"] for r in own if r["status"] == "feasible"] or [None])
        edge = math.inf if smallest is None else smallest
        below = [r for r in own if r["status"] != "feasible" and r["unit_diameter_mm"] < edge]
        first = max(below, key=lambda r: r["unit_diameter_mm"], default={})
        row = {"part": part, "smallest_mm": smallest, "fails_at_mm": first.get("unit_diameter_mm")}
        out.append(row | {key: first.get(key) for key in ("binding", "reason")})
    return out
