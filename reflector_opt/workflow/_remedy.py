"""Where no design exists: the smallest change of the settings that gives one, found by
running the search.

When ``reflector-opt optimise`` finds no design (:class:`~reflector_opt.util._errors.
NoDesignError`: settings no point within the bounds meets, a search with no feasible point,
or a design whose last check fails and cannot be repaired), :func:`smallest_change` tries
changes of the run's settings in rounds of growing size, each by the same search (seed,
budget, starts, part) as the run: in round k the unit diameter k × 0.5 mm larger, the pitch
and roll ranges k° narrower at each end, the minimum wall k × 0.05 mm thinner, the bearing
clearance k × 0.1 mm smaller, the running clearance of the printed parts k × 0.05 mm smaller
(each while it stays positive), then after the first round each other catalogue part. The
first change that gives a design is the answer, with its objective: it was checked by
running it.
"""

import copy
from pathlib import Path

import msgspec

from reflector_opt.util._errors import InputError

#: Rounds of growing changes tried.
ROUNDS = 4

#: The numeric changes of a round: (section, key, step per round); negative steps shrink.
STEPS = (
    ("mechanics", "unit_diameter_mm", 0.5),
    ("workspace", "range_deg", -1.0),
    ("mechanics", "min_wall_mm", -0.05),
    ("constraints", "bearing_clearance_mm", -0.1),
    ("cad", "clearance_mm", -0.05),
)


def _base(document):
    """The settings :data:`STEPS` change, as the document gives them or their defaults."""
    from reflector_opt.design import Mechanics, Workspace
    from reflector_opt.design._parts import CadParameters
    from reflector_opt.optimiser import Problem

    mech, space = Mechanics(), Workspace()
    defaults = {
        ("mechanics", "unit_diameter_mm"): mech.unit_diameter_mm,
        ("workspace", "pitch_deg"): space.pitch_deg,
        ("workspace", "roll_deg"): space.roll_deg,
        ("mechanics", "min_wall_mm"): mech.min_wall_mm,
        ("constraints", "bearing_clearance_mm"): Problem.bearing_clearance_mm,
        ("cad", "clearance_mm"): CadParameters().clearance_mm,
    }
    return {(s, k): document.get(s, {}).get(k, v) for (s, k), v in defaults.items()}


def candidate_changes(document, part, rounds=ROUNDS):
    """The changes :func:`smallest_change` tries, smallest first.

    Parameters
    ----------
    document : dict
        The run's config as parsed TOML (empty for the built-in defaults).
    part : str
        The sensor part of the run (several, by commas: no other part is tried).
    rounds : int, optional

    Returns
    -------
    list of (str, dict, str)
        Each change in words (as a config line or the option), the TOML entries it sets
        (``{(section, key): value}``) and the part it runs with.
    """
    from reflector_opt.model._catalogue import shipped_catalogue

    base = _base(document)
    out = []
    for k in range(1, rounds + 1):
        for section, key, step in STEPS:
            if key == "range_deg":
                ranges = {
                    (section, name): [
                        round(base[section, name][0] - k * step, 9),
                        round(base[section, name][1] + k * step, 9),
                    ]
                    for name in ("pitch_deg", "roll_deg")
                }
                if all(lo < hi for lo, hi in ranges.values()):
                    words = ", ".join(f"{n} = {v}" for (_, n), v in ranges.items())
                    out.append((f"[workspace] {words}", ranges, part))
                continue
            value = round(base[section, key] + k * step, 9)
            if value > 0:
                out.append((f"[{section}] {key} = {value:g}", {(section, key): value}, part))
        if k == 1 and "," not in part:
            others = [p.name for p in shipped_catalogue() if p.name != part]
            out += [(f"--sensor {name}", {}, name) for name in others]
    return out


def _document(config):
    """The run's config as parsed TOML: its file, or empty for the built-in defaults; None
    for a config given as an object (nothing to change in words)."""
    from reflector_opt.util._fileio import read_toml

    if config is None:
        return {}
    return read_toml(config) if isinstance(config, str | Path) else None


def _changed(document, entries):
    out = copy.deepcopy(document)
    for (section, key), value in entries.items():
        out.setdefault(section, {})[key] = value
    return out


def _tried(options, document, entries, part):
    """The objective of the run with the change (degrees), or None if it finds no design:
    the search of ``optimise`` (one part's, or the best of several parts'), without the
    fronts, tolerances or report."""
    from reflector_opt.optimiser._config import parse_config
    from reflector_opt.optimiser._search import optimise
    from reflector_opt.optimiser._sensor_choice import choose_sensor
    from reflector_opt.util._pools import executor_factory
    from reflector_opt.workflow._options import prepare

    changed = msgspec.structs.replace(
        options,
        config=parse_config(_changed(document, entries)),
        sensor=part,
        tolerances=None,
        pareto=False,
        drift_front=False,
        report=False,
    )
    try:
        prepared = prepare(changed)
        config, seed = prepared.config, prepared.seed
        searches = None
        if options.starts > 1 or options.scheduler is not None:
            searches = executor_factory(options.scheduler, config.budget.workers)
        if len(prepared.parts) > 1:
            run = choose_sensor(
                config.problem, prepared.parts, seed=seed, budget=config.budget, executor=searches
            ).result
        else:
            run = optimise(
                config.problem,
                seed=seed,
                budget=config.budget,
                starts=options.starts,
                executor=searches,
            )
    except InputError:
        return None
    return float(run.evaluation.objective)


def _pointer(document, part):
    """The ``smallest`` command for this part and workspace."""
    base = _base(document)
    w = max(abs(v) for name in ("pitch_deg", "roll_deg") for v in base["workspace", name])
    return (
        f"`reflector-opt smallest --sensor {part} --workspace-deg {w:g} --target-deg X` "
        "finds the smallest unit that meets a target X (docs/smallest.md)"
    )


def _part(options, document):
    """The run's sensor part: ``--sensor``'s, else the config's ``[sensor] model``."""
    from reflector_opt.optimiser import Problem

    if options.sensor is not None:
        return options.sensor
    return document.get("sensor", {}).get("model", Problem().sensor.name)


def smallest_change(options, progress=None):
    """The smallest change of ``options``' settings that gives a design, in one sentence.

    Parameters
    ----------
    options : reflector_opt.workflow._options.OptimiseOptions
        The run that found no design.
    progress : callable, optional
        ``progress(fraction, message)``.

    Returns
    -------
    str
        The change (a config line or ``--sensor PART``) and the objective the search found
        with it, or what was tried; then the ``smallest`` command to run.
    """
    document = _document(options.config)
    if document is None:
        part = options.sensor or options.config.problem.sensor.name
        return "no change tried (the config is an object, not a file); " + _pointer({}, part)
    part = _part(options, document)
    changes = candidate_changes(document, part)
    for i, (words, entries, trial_part) in enumerate(changes):
        if progress is not None:
            progress(i / len(changes), f"no design; trying {words}")
        try:
            objective = _tried(options, document, entries, trial_part)
        except InputError:  # the change itself is refused (e.g. a bearing wider than the unit)
            objective = None
        if objective is not None:
            return (
                f"the smallest change found that gives a design (searched with the same seed "
                f"and budget): {words} (objective {objective:.4g}°); " + _pointer(document, part)
            )
    return (
        f"none of {len(changes)} changes tried gives a design (up to {ROUNDS} steps of the unit "
        "diameter, workspace, minimum wall, bearing and running clearances, and every other "
        "catalogue part); " + _pointer(document, part)
    )
