"""The options of an optimisation run, as ``reflector-opt optimise`` takes them, and their
resolution into the settings the search needs: the configuration (with the operating
conditions of ``--conditions``), the seed, the tolerance model of a robust run and the sensor
parts.

Every check that needs no search runs here, before any work, so that a run refused for its
options has computed and written nothing.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import MAX_STARTS, MAX_WORKERS

__all__ = ["OptimiseOptions", "Prepared", "prepare"]


@dataclass(frozen=True)
class OptimiseOptions:
    """What to optimise and what to write: the options of ``reflector-opt optimise``.

    Attributes
    ----------
    config : reflector_opt.optimiser._config.OptimiseConfig, str, pathlib.Path or None
        The settings, or a TOML file of them (``--config``; docs/optimiser.md); None for the
        built-in defaults.
    seed : int or None
        Seed of the search (``--seed``); None for the config's.
    surface : str or None
        A surface preset of :data:`reflector_opt.model._surface.MATERIALS` to design for
        (``--surface``); None for the config's.
    sensor : str or None
        ``auto``, part names or ``PARTS.toml`` files separated by commas (``--sensor``): each
        part that fits is optimised and the best kept; None for the config's ``[sensor]``.
    starts : int
        Independent searches from derived seeds, the best kept (``--starts``, 1–256).
    workers : int or None
        Worker processes of the search (``--workers``, 1–256); None for the config's.
    pareto : bool
        Also trace resolution against distance margin (``--pareto``; ``pareto.json``,
        ``pareto.png``).
    tolerances : reflector_opt.tolerance._config.ToleranceConfig, str, pathlib.Path or None
        Optimise robustly against these tolerances, or a TOML file of them (``--tolerances``).
    scheduler : str or None
        Address of a Dask scheduler for the searches of ``starts`` or of several parts and for
        the tolerance studies (``--scheduler``); None for local processes.
    report : bool
        Write the report, the predicted calibration errors and the printable parts (False:
        ``--no-report``).
    conditions : reflector_opt.design._conditions.Conditions, str, pathlib.Path or None
        Operating conditions, or their TOML file (``--conditions``; docs/conditions.md): the
        conditions the design is judged in. They replace the config's ``[conditions]``; None
        for the config's, or the default conditions where it has none.
    drift_front : bool
        Also trace white-noise resolution against drift sensitivity (``--drift-front``;
        ``drift_front.json``).
    objective : str
        What the search minimises, one of
        :data:`~reflector_opt.util._limits.OBJECTIVES` (``--objective``): ``"in-use"``,
        the worst-case total error in the conditions, or ``"resolution"``, the worst-case
        white-noise resolution (the design then judged in the conditions afterwards).
    read_out : str
        ``"chosen"`` (``--read-out``): the drive, sample rate and temperature compensation are
        the optimiser's to choose (:mod:`~reflector_opt.optimiser._readout`), the conditions'
        being the default design's; ``"stated"`` keeps the conditions' own.
    """

    config: object = None
    seed: int | None = None
    surface: str | None = None
    sensor: str | None = None
    starts: int = 1
    workers: int | None = None
    pareto: bool = False
    tolerances: object = None
    scheduler: str | None = None
    report: bool = True
    conditions: object = None
    drift_front: bool = False
    objective: str = "in-use"
    read_out: str = "chosen"


#: The values of :attr:`OptimiseOptions.read_out`.
READ_OUTS = ("chosen", "stated")


@dataclass(frozen=True)
class Prepared:
    """Options resolved into what the search takes.

    Attributes
    ----------
    config : reflector_opt.optimiser._config.OptimiseConfig
        With the surface, the workers and a single sensor part applied.
    seed : int
    tolerance : reflector_opt.tolerance._config.ToleranceConfig or None
        The tolerance model of a robust run.
    parts : list
        The catalogue parts of ``sensor`` (empty without it).
    conditions : reflector_opt.design._conditions.Conditions
        The conditions the design is judged in, as stated (the search's are the config's
        problem's: these under ``"in-use"``, None under ``"resolution"``).
    """

    config: object
    seed: int
    tolerance: object
    parts: list
    conditions: object = None


def _count(value, name, high):
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= high:
        raise InputError(f"--{name}: {value!r} is not a whole number from 1 to {high}")
    return value


def _config(options):
    """The configuration of ``options``, with its surface, workers and the search's conditions
    applied, and the conditions the design is judged in."""
    from reflector_opt.model._surface import get_material
    from reflector_opt.optimiser._config import OptimiseConfig, load_config

    config = options.config
    if config is None:
        config = OptimiseConfig()
    elif isinstance(config, str | Path):
        config = load_config(config)
    if options.surface is not None:
        surface = get_material(options.surface)
        config = replace(config, problem=replace(config.problem, surface=surface))
    if options.workers is not None:
        workers = _count(options.workers, "workers", MAX_WORKERS)
        config = replace(config, budget=replace(config.budget, workers=workers))
    from reflector_opt.optimiser._conditions import search_conditions

    if options.read_out not in READ_OUTS:
        raise InputError(f"--read-out: {options.read_out!r} is not one of {', '.join(READ_OUTS)}")
    given = _conditions(options.conditions)
    judged = search_conditions("in-use", config.problem.conditions if given is None else given)
    searched = search_conditions(options.objective, judged)
    return replace(config, problem=replace(config.problem, conditions=searched)), judged


def _conditions(given):
    """The operating conditions of ``--conditions`` (None without them)."""
    from reflector_opt.design._conditions import Conditions, as_conditions

    if not isinstance(given, Conditions | str | Path | None):
        raise InputError(
            f"--conditions: expected Conditions or a TOML file, got {type(given).__name__}"
        )
    return as_conditions(given)


def _tolerance(options):
    """The tolerance model of ``options`` (None without one)."""
    if options.tolerances is None or not isinstance(options.tolerances, str | Path):
        return options.tolerances
    from reflector_opt.tolerance._config import load_tolerance_config

    return load_tolerance_config(options.tolerances)


def _parts(options, tolerance):
    """The parts of ``sensor`` (none without it); several exclude the one-search options."""
    if options.sensor is None:
        return []
    from reflector_opt.model._catalogue import resolve_parts

    parts = resolve_parts(options.sensor)
    if len(parts) > 1:
        for given, option in (
            (tolerance is not None, "--tolerances"),
            (options.pareto, "--pareto"),
            (options.drift_front, "--drift-front"),
            (options.starts > 1, "--starts"),
        ):
            if given:
                raise InputError(
                    f"--sensor: {len(parts)} parts, not with {option}; choose the part first, "
                    f"then run {option} with --sensor PART"
                )
    return parts


def prepare(options):
    """Resolve and check ``options`` before any work.

    Parameters
    ----------
    options : OptimiseOptions

    Returns
    -------
    Prepared

    Raises
    ------
    InputError
        A file that cannot be read (conditions too), an unknown surface or part, a count out
        of range, or options that cannot go together (``starts`` with ``tolerances``; several
        parts with ``tolerances``, ``pareto``, ``drift_front`` or ``starts``; a scheduler
        with nothing to distribute). The message names the option as the command line
        spells it.
    """
    config, conditions = _config(options)
    seed = config.seed if options.seed is None else options.seed
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError(f"--seed: expected a whole number ≥ 0, got {seed!r}")
    _count(options.starts, "starts", MAX_STARTS)
    tolerance = _tolerance(options)
    if options.starts > 1 and tolerance is not None:
        raise InputError("--starts: not with --tolerances (each robust round runs one search)")
    parts = _parts(options, tolerance)
    if len(parts) == 1:
        from reflector_opt.optimiser._sensor_choice import part_problem

        config = replace(config, problem=part_problem(config.problem, parts[0]))
    if options.scheduler is not None and tolerance is None and options.starts == 1:
        if len(parts) < 2:
            raise InputError(
                "--scheduler runs the searches of --starts or of a --sensor list and the "
                "tolerance studies: give --starts N or --tolerances FILE.toml, or --sensor with "
                "several parts"
            )
    return Prepared(config, seed, tolerance, parts, conditions)
