"""The optimiser picks the part: one design per catalogue part that fits, ranked.

The sensor is the first design variable, and a discrete one: it decides the usable range, the
shape of the response and the package the body must hold. :func:`choose_sensor` optimises the
design for each part of a list (:func:`~reflector_opt.model._catalogue.resolve_parts`: the
catalogue, or some of its parts, or a user's part file) as independent tasks on local
processes or a Dask cluster (:mod:`reflector_opt.util._pools`), ranks the verified
designs and returns the best, its ``predicted`` block carrying the part's catalogue record and
the ranking (``predicted["sensor_choice"]``).

Each part is judged under the same problem, with three things its own
(:func:`part_problem`): the sensor model; the package, which sets the body's windows and the
wall above them (:func:`~reflector_opt.design._parts.package_parameters`); and the radial room
behind the sensor's face, ``sensor_backing_mm``, which grows by as much as the package is deeper
than the CAD parameters' (the room the configured backing was set for). A part that cannot be
laid out in the unit is skipped with the reason: settings no design can meet
(:class:`~reflector_opt.optimiser._problem.Problem` refuses them before any search: a package
too deep for the envelope, a usable range that leaves no shell wall above the bearing), or a
search that finds no design passing every constraint and the printed walls.

The ranking orders the parts by what a unit meets in use: in operating conditions (the
optimiser's default objective), each part's in-use worst-case total error in them
(:attr:`ErrorBudget.worst_case_deg <reflector_opt.analysis._budget.ErrorBudget.worst_case_deg>`
of its optimised design, each part with its own temperature figures from the catalogue,
:func:`~reflector_opt.analysis._budget.thermal_coefficients_of`), its white-noise floor (the
worst 1σ resolution) shown beside it; without conditions (``--objective resolution``), by the
optimised objective, the worst-case 1σ resolution with the isotropy weight. Compared to three
significant figures; ties go to the smaller predicted
calibration error (:func:`calibration_error`, two significant figures), then to the larger
distance-window margin, then to the smaller body (the radius the sensors and their backing
reach, ``sensor_envelope_mm``).
"""

import dataclasses
import functools
import math

from reflector_opt.design._parts import package_parameters
from reflector_opt.optimiser._studies import Variant, optimise_variants
from reflector_opt.optimiser._variables import default_bounds
from reflector_opt.util._display import Summarised, fmt, more_rows
from reflector_opt.util._errors import InputError, NoDesignError

#: Built units per part of the ranking's predicted calibration error (``evaluate`` and the
#: report use the design's ``mechanics.n_units``, 4 by default; one keeps the ranking within
#: seconds).
CALIBRATION_UNITS = 1


def calibration_error(design, seed=0):
    """Predicted calibration error of a design with its recommended calibration, degrees.

    :func:`~reflector_opt.tolerance._prediction.predicted_performance` (the prediction of
    ``evaluate`` and the report: built units with exact optics, calibrated on the
    recommended plan with the form chosen by cross-validation, validated on random poses with
    the true angles) on :data:`CALIBRATION_UNITS` built unit.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    seed : int, optional
        Seed of the built unit and the simulated calibration.

    Returns
    -------
    dict or None
        ``{"pitch": rms, "roll": rms}`` (degrees, RMS over the validation poses), None for a
        design without exactly two sensors.
    """
    from reflector_opt.tolerance._prediction import predicted_performance

    mechanics = dataclasses.replace(design.mechanics, n_units=CALIBRATION_UNITS)
    predicted = predicted_performance(design.replace(mechanics=mechanics), seed=seed)
    if predicted.calibration is None:
        return None
    return predicted.calibration.recommended.rms_deg.to_dict()


def part_problem(problem, part):
    """The problem with a catalogue part for both sensors.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
        The settings (workspace, envelope, noise, limits, CAD parameters); bounds it states
        that differ from its own part's defaults are kept, the others follow the new part.
    part : reflector_opt.model._catalogue.CataloguePart

    Returns
    -------
    Problem
        Raises :class:`~reflector_opt.util._errors.InputError` (prefixed with the part's name
        and package) when no design within the bounds can meet the settings with this part.
    """
    try:
        return _part_problem(problem, part)
    except InputError as exc:
        raise type(exc)(f"{part.name} ({_package(part)} mm): {exc}") from None


def _part_problem(problem, part):
    old = default_bounds(
        problem.sensor,
        problem.mechanics,
        sensor_backing_mm=problem.sensor_backing_mm,
        bearing_clearance_mm=problem.bearing_clearance_mm,
    )
    stated = {k: v for k, v in problem.bounds.items() if tuple(old[k]) != tuple(v)}
    depth = part.package_mm[2]
    backing = round(problem.sensor_backing_mm + (depth - problem.cad.sensor_depth_mm), 9)
    if backing <= 0:
        raise InputError("sensor_backing_mm: the package leaves no room behind the sensor")
    return dataclasses.replace(
        problem,
        sensor=part.model,
        cad=package_parameters(problem.cad, [part.model]),
        sensor_backing_mm=backing,
        bounds=stated,
    )


def _package(part):
    return " × ".join(f"{v:g}" for v in part.package_mm)


@dataclasses.dataclass(frozen=True, repr=False)
class SensorChoice(Summarised):
    """What :func:`choose_sensor` found.

    Attributes
    ----------
    result : reflector_opt.optimiser._result.OptimisationResult
        The best part's optimisation; its design's ``predicted["sensor_choice"]`` is
        :attr:`record`.
    part : reflector_opt.model._catalogue.CataloguePart
        The best part.
    record : dict
        ``chosen`` (the part's name), ``part`` (its catalogue record: figures, sources, basis),
        ``criteria`` and ``ranking``: one row per part, ranked ones first, with ``rank``,
        ``part``, ``maker``, ``package_mm``, ``status`` (``"ranked"`` or ``"skipped"``) and
        either ``objective_deg``, ``worst_pitch_deg``, ``worst_roll_deg``, ``margin_mm``,
        ``body_radius_mm``, ``seconds`` or the ``reason``. In operating conditions the
        record also holds them (``conditions``) and each ranked row its
        ``worst_case_deg`` and the ``thermal_coefficients`` its budget used.
    """

    result: object
    part: object
    record: dict

    def _summary(self):
        """Title and (label, value) rows of :class:`SensorChoice`."""
        ranking = self.record.get("ranking", [])
        rows = [
            ("objective", fmt(self.result.objective, unit="°")),
            (
                "package",
                " × ".join(fmt(v) for v in self.part.package_mm) + " mm"
                if self.part.package_mm
                else "n/a",
            ),
        ]
        for row in ranking[:SHOWN_PARTS]:
            if row.get("status") == "ranked":
                value = f"objective {fmt(row.get('objective_deg'), unit='°')}, "
                if "worst_case_deg" in row:
                    value = f"in-use worst case {fmt(row['worst_case_deg'], unit='°')}, "
                value += f"margin {fmt(row.get('margin_mm'), unit='mm')}"
            else:
                value = f"skipped: {row.get('reason')}"
            rows.append((f"#{row.get('rank') or '-'} {row.get('part')}", value))
        rows += more_rows(len(ranking), SHOWN_PARTS, "parts")
        return f"SensorChoice: {self.part.name} ({self.part.maker})", rows


def _calibration(result, problem):
    """The figures of a part's optimisation: its predicted calibration error."""
    return {"calibration_rms_deg": calibration_error(result.design, result.seed)}


def _row(variant):
    """The ranking's row of a part's :class:`~reflector_opt.optimiser._studies.Variant`."""
    part, result, problem = variant.value, variant.result, variant.problem
    row = {"part": part.name, "maker": part.maker, "package_mm": list(part.package_mm)}
    if result is None:
        return {**row, "status": "skipped", "reason": variant.reason}
    constraints = result.evaluation.constraints_dict()
    resolution = result.metrics.to_dict()["resolution_deg"]
    budget = result.evaluation.budget
    if budget is not None:
        from reflector_opt.analysis._budget import thermal_coefficients_of

        thermal = thermal_coefficients_of([part.model])[0]
        row["worst_case_deg"] = budget.worst_case_deg
        row["thermal_coefficients"] = dataclasses.asdict(thermal)
    return {
        **row,
        "status": "ranked",
        "objective_deg": float(result.objective),
        "worst_pitch_deg": resolution["pitch_worst"],
        "worst_roll_deg": resolution["roll_worst"],
        "calibration_rms_deg": variant.figures.get("calibration_rms_deg"),
        "margin_mm": constraints["distance_margin_mm"]["value"],
        "body_radius_mm": constraints["sensor_envelope_mm"]["value"],
        "sensor_backing_mm": problem.sensor_backing_mm,
        "seconds": round(variant.seconds, 2),
    }


def rank_key(row):
    """Sort key of a ranked row: the ranking's criteria in order (smaller is better), the
    first its in-use worst case where it has one (``worst_case_deg``), else its objective."""
    error = row["calibration_rms_deg"]
    worst = math.inf if error is None else float(f"{max(error.values()):.2g}")
    first = row.get("worst_case_deg", row["objective_deg"])
    return (float(f"{first:.3g}"), worst, -row["margin_mm"], row["body_radius_mm"])


def choose_sensor(problem, parts, *, seed=0, budget=None, executor=None, progress=None):
    """Optimise the design for each part, rank the parts and return the best.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
        The settings every part is judged under (:func:`part_problem`).
    parts : sequence of reflector_opt.model._catalogue.CataloguePart
    seed : int, optional
        Seed of every part's search.
    budget : reflector_opt.optimiser._search.SearchBudget, optional
        The search's work. With one part to search it runs in this process with
        ``budget.workers`` workers; with more, each part's search is a task of ``executor``
        in one process (the same design as in this process).
    executor : callable, optional
        Executor factory (:mod:`reflector_opt.util._pools`) for the parts; default
        ``budget.workers`` local spawned processes.
    progress : callable, optional
        ``progress(fraction, message)``.

    Returns
    -------
    SensorChoice
        Raises :class:`~reflector_opt.util._errors.InputError` when no part fits (one line
        with each part's reason).
    """
    if not parts:
        raise InputError("--sensor: no parts to choose from")
    found = optimise_variants(
        [(part.name, part) for part in parts],
        functools.partial(_part_problem, problem),
        seed=seed,
        budget=budget,
        figures=_calibration,
        executor=executor,
        progress=progress,
    )
    best, record = _ranked(parts, [_row(v) for v in found], seed, problem.conditions)
    return _chosen(next(v.result for v in found if v.value.name == best.name), best, record)


def _criteria(conditions):
    """What the ranking orders by, in words."""
    first = (
        "objective (worst-case 1σ resolution, isotropy-weighted)"
        if conditions is None
        else "the in-use worst-case total error in the conditions (each part with its "
        "catalogue temperature figures; its white-noise floor beside it)"
    )
    return (
        f"{first} to 3 significant figures, then the smaller predicted calibration error (RMS, "
        "the worse angle) to 2, then the larger distance margin, then the smaller body radius"
    )


def _ranked(parts, rows, seed, conditions=None):
    """The best part and the ``sensor_choice`` record of the rows (``conditions``: the
    problem's operating conditions, or None)."""
    ranked = sorted((r for r in rows if r["status"] == "ranked"), key=rank_key)
    if not ranked:
        raise NoDesignError(
            "no sensor part fits the unit: "
            + "; ".join(f"{r['part']}: {r['reason']}" for r in rows)
        )
    skipped = [r for r in rows if r["status"] == "skipped"]
    for i, row in enumerate(ranked, start=1):
        row["rank"] = i
    best = next(p for p in parts if p.name == ranked[0]["part"])
    record = {
        "chosen": best.name,
        "part": best.record(),
        "criteria": _criteria(conditions),
        "calibration": f"recommended calibration of {CALIBRATION_UNITS} built unit "
        "(tolerance.prediction.predicted_performance)",
        "seed": seed,
        "ranking": ranked + skipped,
    }
    if conditions is not None:
        record["conditions"] = conditions.to_dict()
    return best, record


def _chosen(result, part, record):
    design = result.design.replace(predicted=result.design.predicted.replace(sensor_choice=record))
    return SensorChoice(dataclasses.replace(result, design=design), part, record)


def record_part(result, part, problem, seed):
    """An optimisation of one given part, with its catalogue record and one-row ranking.

    With nothing to rank against, the row has no predicted calibration error
    (``calibration_rms_deg`` None, shown as n/a), which would cost a simulated calibration
    here; ``evaluate`` and the report predict it on all the design's units.

    Parameters
    ----------
    result : reflector_opt.optimiser._result.OptimisationResult
        The optimisation under ``problem`` (any kind: single, multi-start, robust).
    part : reflector_opt.model._catalogue.CataloguePart
    problem : reflector_opt.optimiser._problem.Problem
        :func:`part_problem` of the part.
    seed : int

    Returns
    -------
    reflector_opt.optimiser._result.OptimisationResult
        ``result`` with ``predicted["sensor_choice"]`` in its design.
    """
    row = _row(Variant(part.name, part, problem, result, seconds=sum(result.seconds.values())))
    best, record = _ranked([part], [row], seed, problem.conditions)
    return _chosen(result, best, record).result


#: Ranked parts a display lists; the rest are counted.
SHOWN_PARTS = 10
