"""Design sweeps: nominal performance and tolerance yield over a grid of design variables.

A variable is a number in the design document (``design.json``), named by its path:
``reflector.radius_mm``, ``reflector.centre_mm[2]``, ``sensors[0].position_mm[0]``,
``noise.sigma_v`` … Its values are ``START:STOP:N`` (N evenly spaced values, both ends
included) or a comma-separated list. The grid is the Cartesian product of all variables; each
point is read and checked as ``evaluate`` reads a design, then analysed like a
tolerance-study sample with every tolerance off (its nominal performance, with the in-use
worst-case error of :func:`~reflector_opt.analysis._budget.error_budget` in operating
conditions, the default ones where none are given, beside the white-noise resolution) and,
with ``samples > 0``, by a Monte Carlo sample of that many units (its yield). A value the design
document refuses (a fractional unit count, a grid step beyond the limits) refuses the sweep
before any work; a point that is not a design that can be built (e.g. a sensor inside the
sphere) is reported as such, not raised. All points run as batches on one executor, with the
draws of :func:`run_study` (the same seed gives the same units at every point: common random
numbers).
"""

import itertools
import math
import re

import numpy as np

from reflector_opt.design import Design
from reflector_opt.design._conditions import Conditions
from reflector_opt.design._designfile import design_fields_from_dict
from reflector_opt.tolerance._analysis import Job, Settings, Targets, check_work, evaluate_part
from reflector_opt.tolerance._statistics import summarise
from reflector_opt.tolerance._study import BATCH_SIZE, batched
from reflector_opt.tolerance._tolerances import Tolerances, draw_sample
from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import MAX_SWEEP_POINTS, check_size
from reflector_opt.util._pools import local_processes, run_batches

_STEP = re.compile(r"([A-Za-z_]\w*)((?:\[\d+\])*)")


def _steps(path):
    steps = []
    for part in path.split("."):
        match = _STEP.fullmatch(part)
        if not match:
            raise InputError(f"variable {path!r}: expected a path like reflector.centre_mm[2]")
        steps.append(match.group(1))
        steps.extend(int(i) for i in re.findall(r"\[(\d+)\]", match.group(2)))
    return steps


def set_value(document, path, value):
    """Copy of a design document with the number at ``path`` replaced by ``value``.

    Parameters
    ----------
    document : dict
        A ``design.json`` document (:meth:`Design.to_dict`).
    path : str
        E.g. ``"sensors[1].axis[0]"``.
    value : float
        Written as an int where the design holds an int and ``value`` is whole.

    Returns
    -------
    dict
    """
    import copy

    out = copy.deepcopy(document)
    node, steps = out, _steps(path)
    for step in steps:
        try:
            parent, node = node, node[step]
        except (KeyError, IndexError, TypeError):
            raise InputError(f"variable {path!r}: the design has no {step!r} there") from None
    if isinstance(node, bool) or not isinstance(node, int | float):
        raise InputError(f"variable {path!r}: not a number in the design")
    value = float(value)
    # A whole number stays one where the design holds one (mechanics.n_units, noise.adc_bits):
    # the schema refuses 2.0 where it expects a whole number.
    parent[steps[-1]] = int(value) if isinstance(node, int) and value.is_integer() else value
    return out


def parse_variable(spec):
    """Parse ``PATH=START:STOP:N`` or ``PATH=V1,V2,…`` into ``(path, values)``.

    Returns
    -------
    tuple of (str, list of float)
    """
    if "=" not in spec:
        raise InputError(f"--vary {spec!r}: expected PATH=START:STOP:N or PATH=V1,V2,…")
    path, _, text = spec.partition("=")
    path = path.strip()
    _steps(path)
    try:
        if ":" in text:
            start, stop, count = text.split(":")
            n = int(count)
            if n < 1:
                raise ValueError
            check_size(n, f"--vary {path}", MAX_SWEEP_POINTS, "values")
            values = np.linspace(float(start), float(stop), n).tolist()
        else:
            cells = text.split(",")
            check_size(len(cells), f"--vary {path}", MAX_SWEEP_POINTS, "values")
            values = [float(v) for v in cells]
    except InputError:
        raise
    except ValueError:
        raise InputError(
            f"--vary {spec!r}: expected START:STOP:N (N ≥ 1) or numbers separated by commas"
        ) from None
    if not all(math.isfinite(v) for v in values):
        raise InputError(f"--vary {spec!r}: values must be finite")
    return path, values


def sweep(
    design,
    variables,
    tolerances=None,
    *,
    samples=0,
    seed=0,
    settings=None,
    targets=None,
    factory=None,
    batch_size=BATCH_SIZE,
    progress=None,
    conditions=None,
):
    """Nominal performance and yield at every point of a grid of design variables.

    Every point is read as ``evaluate`` reads a design, before any work starts: a value the
    design document refuses (its schema or a part's own checks: a fractional
    ``mechanics.n_units``, a grid step beyond the limits, a zero axis) is bad input and
    refuses the whole sweep; a point whose parts do not fit together (a sensor inside the
    sphere, parts that cannot be laid out: :func:`~reflector_opt.design._layout.plan_layout`)
    is a design that cannot be built, and its row says why.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        The design the variables are changed in.
    variables : list of (str, list of float)
        Paths and their values (:func:`parse_variable`).
    tolerances : Tolerances, optional
    samples : int
        Monte Carlo units per point (0: nominal performance only).
    seed : int
    settings, targets : optional
        As in :func:`reflector_opt.tolerance._study.run_study`.
    factory : callable, optional
        Executor factory; default two local processes.
    batch_size : int
    progress : callable, optional
    conditions : reflector_opt.design._conditions.Conditions, optional
        The operating conditions each point's in-use worst case is judged in; the default
        conditions if None.

    Returns
    -------
    list of dict
        One row per point: the variable values, ``status`` (``"ok"`` or ``"invalid: "`` and
        the reason the point is not a design that can be built), the nominal outputs
        (``nominal_`` + the record's outputs, and ``nominal_worst_case_deg``: the in-use
        worst-case total error, :attr:`ErrorBudget.worst_case_deg
        <reflector_opt.analysis._budget.ErrorBudget.worst_case_deg>`) and, with samples, ``yield``,
        ``yield_window`` and the median and p95 of the worse RMS error.

    Raises
    ------
    InputError
        A bad argument, a path the design does not have, a point whose value the design
        refuses (``--vary POINT: …``), or work beyond the limits of one run.
    """
    tolerances = Tolerances() if tolerances is None else tolerances
    settings = Settings() if settings is None else settings
    targets = Targets() if targets is None else targets
    rows, variants = _checked_points(design, variables, samples, settings)
    factory = local_processes() if factory is None else factory
    draws = [draw_sample(tolerances, len(design.sensors), seed, i) for i in range(max(samples, 1))]
    batches, owners = [], []
    for i, variant in enumerate(variants):
        if variant is None:
            continue
        parts = [("nominal", Job(variant, Tolerances.zero(), settings), draws[:1])]
        if samples:
            parts.append(("sample", Job(variant, tolerances, settings), draws))
        for kind, job, part in parts:
            for chunk in batched(part, batch_size):
                batches.append((job, chunk, kind))
                owners.append((i, kind))
    conditions = Conditions() if conditions is None else conditions
    results = run_batches(_evaluate_point_part, conditions, batches, factory, progress=progress)
    collected = {}
    for owner, batch in zip(owners, results, strict=True):
        collected.setdefault(owner, {}).update((r["index"], r) for r in batch)
    for i, row in enumerate(rows):
        if row["status"] == "ok":
            _fill(row, collected, i, targets)
    columns = dict.fromkeys(k for row in rows for k in row)  # in order of first appearance
    return [{k: row.get(k, math.nan) for k in columns} for row in rows]


def _checked_points(design, variables, samples, settings):
    """The grid's rows and designs (:func:`_points`), once the arguments, every path and the
    work of the whole sweep are checked (InputError before any work starts)."""
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 0:
        raise InputError(f"samples: must be a whole number ≥ 0, got {samples!r}")
    if not variables:
        raise InputError("sweep: give at least one variable (--vary PATH=START:STOP:N)")
    document = design.to_dict()
    for path, _ in variables:
        set_value(document, path, 0.0)  # a wrong path fails now, before any work
    points = math.prod(len(values) for _, values in variables)
    check_size(points, "--vary (the product of the value counts)", MAX_SWEEP_POINTS, "points")
    where = "sweep points × (1 + samples)"
    check_work(design.workspace, settings, points * (1 + samples), where)  # at once
    rows, variants = _points(document, variables)
    widest = max(
        (v.workspace for v in variants if v is not None),
        key=settings.poses_per_unit,
        default=design.workspace,
    )
    check_work(widest, settings, points * (1 + samples), where)  # a workspace varied
    return rows, variants


def _points(document, variables):
    """The rows of the grid's points and their designs (None where one cannot be built).

    A value the design document refuses raises :class:`InputError` naming the point; a
    design whose parts do not fit together is its row's ``status``.
    """
    rows, variants = [], []
    for values in itertools.product(*(v for _, v in variables)):
        row = {path: value for (path, _), value in zip(variables, values, strict=True)}
        point = document
        for path, value in row.items():
            point = set_value(point, path, value)
        try:
            fields = design_fields_from_dict(point)
        except InputError as exc:
            shown = ", ".join(f"{path}={value:g}" for path, value in row.items())
            raise InputError(f"--vary {shown}: {exc}") from None
        try:
            variant = Design(**fields)
        except InputError as exc:
            row["status"], variant = f"invalid: {exc}", None
        else:
            row["status"] = "ok"
        rows.append(row)
        variants.append(variant)
    return rows, variants


def _evaluate_point_part(conditions, part):
    """Entry point of a sweep's batches: ``part`` is ``(job, draws, kind)``.

    The nominal part (``kind`` ``"nominal"``) first lays out the point's printable parts, as
    ``evaluate`` does (:func:`~reflector_opt.design._layout.plan_layout`, in the workers: it
    costs about as much as the point's evaluation); where they cannot be laid out, its one
    record is ``{"index": …, "layout": reason}``. Otherwise the records of
    :func:`~reflector_opt.tolerance._analysis.evaluate_part`, the nominal one with its
    ``worst_case_deg`` in ``conditions`` (:func:`~reflector_opt.analysis._budget.error_budget`).
    """
    job, draws, kind = part
    if kind == "nominal":
        from reflector_opt.analysis._budget import error_budget
        from reflector_opt.design._layout import plan_layout

        try:
            plan_layout(job.design)
            worst = error_budget(job.design, conditions).worst_case_deg
        except InputError as exc:
            return [{"index": draws[0].index, "layout": str(exc)}]
        return [r | {"worst_case_deg": worst} for r in evaluate_part(None, (job, draws))]
    return evaluate_part(None, (job, draws))


def _fill(row, collected, i, targets):
    """Add point ``i``'s nominal outputs and, if sampled, its yield to its row (or, where its
    parts cannot be laid out, the reason as its status)."""
    nominal = collected[(i, "nominal")][0]
    if "layout" in nominal:
        row["status"] = f"invalid: {nominal['layout']}"
        return
    for key in (
        "status",
        "worst_case_deg",
        "window_kept",
        "distance_margin_mm",
        "rms_pitch_deg",
        "rms_roll_deg",
        "max_pitch_deg",
        "max_roll_deg",
        "resolution_pitch_deg",
        "resolution_roll_deg",
        "wall_min_mm",
    ):
        row[f"nominal_{key}"] = nominal[key]
    if (i, "sample") not in collected:
        return
    table = collected[(i, "sample")]
    summary = summarise([table[k] for k in sorted(table)], targets)
    worse = summary["distributions"]
    row["yield"] = summary["yield"]["all"]
    row["yield_window"] = summary["yield"]["window"]
    for angle in ("pitch", "roll"):
        d = worse[f"rms_{angle}_deg"]
        row[f"rms_{angle}_median_deg"] = d["median"] if d else math.nan
        row[f"rms_{angle}_p95_deg"] = d["p95"] if d else math.nan
