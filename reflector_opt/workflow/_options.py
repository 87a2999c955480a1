"""The options of an optimisation run, as ``reflector-opt optimise`` takes them, and their
resolution into the settings the search needs: the configuration (with the operating
conditions of ``--conditions``), the seed, the tolerance model of a robust run and the sensor
parts.

Every check that needs no search runs here, before any work, so that a run refused for its
options has computed and written nothing.
"""

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal

from reflector_opt.model._surface import DEFAULT_MATERIAL, MATERIALS, get_material
from reflector_opt.util._declared import Options, Seed, Starts, Workers, option
from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import OBJECTIVES

#: The values of :attr:`OptimiseOptions.read_out`.
READ_OUTS = ("chosen", "stated")

_SURFACES = ", ".join(
    f"{m.name} (ρ {m.reflectance}, f {m.specular_fraction})" for m in MATERIALS.values()
)


class OptimiseOptions(Options):
    """What to optimise and what to write: the options of ``reflector-opt optimise``, each
    declared once (:mod:`reflector_opt.util._declared`); docs/cli.md lists them."""

    config: option(
        object,
        "settings: an OptimiseConfig or its TOML file (docs/optimiser.md); the built-in "
        "defaults if left out",
        metavar="FILE.toml",
    ) = None
    seed: option(Seed, "seed of the search; the config's [search] seed if left out") | None = None
    surface: option(
        Literal[tuple(sorted(MATERIALS))] | None,
        f"the reflector's surface to design for: {_SURFACES}; the config's if left out "
        f"({DEFAULT_MATERIAL} by default)",
    ) = None
    sensor: option(
        str | None,
        "the sensor part: auto (every part of the sensor catalogue), part names or PARTS.toml "
        "catalogue files, separated by commas; each part that fits the unit is optimised (in "
        "parallel on --workers processes, or on --scheduler) and the best kept; replaces the "
        "config's [sensor]",
        metavar="PARTS",
    ) = None
    conditions: option(
        object,
        "operating conditions (Conditions, or a [conditions] TOML file, docs/conditions.md) "
        "the design is judged in; replaces the config's [conditions]; the config's, or the "
        "default conditions, if left out",
        metavar="COND.toml",
    ) = None
    objective: option(
        Literal[OBJECTIVES],
        "in-use: the worst-case total error in the conditions (the default conditions, "
        "docs/conditions.md, where none are given); resolution: the worst-case white-noise "
        "resolution, the conditions then only judging the result",
    ) = OBJECTIVES[0]
    read_out: option(
        Literal[READ_OUTS],
        "chosen: the optimiser chooses the drive, sample rate and temperature compensation "
        "with the geometry, the conditions' being the default design's; stated: keep the "
        "conditions' own",
    ) = READ_OUTS[0]
    starts: Starts = 1
    workers: (
        option(
            Workers,
            "worker processes of the search; the config's [search] workers if left out",
        )
        | None
    ) = None
    pareto: option(
        bool, "also trace resolution against distance margin (pareto.json, pareto.png; slow)"
    ) = False
    drift_front: option(
        bool,
        "also trace white-noise resolution against drift sensitivity (drift_front.json; "
        "slow), with each design's total error in the conditions",
    ) = False
    tolerances: option(
        object,
        "optimise robustly against these tolerances (a ToleranceConfig or the TOML file of "
        "`tolerance --tolerances`): the distance margin is raised until it covers [robust] "
        "coverage of built units; with --pareto, each point gets its yield",
        metavar="FILE.toml",
    ) = None
    scheduler: option(
        str | None,
        "run the searches of --starts or of several --sensor parts and the tolerance studies "
        "on a Dask scheduler, e.g. tcp://host:8786",
        metavar="ADDRESS",
    ) = None
    report: option(
        bool,
        "write the report, the predicted calibration errors and the printable parts",
    ) = True


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


def _config(options):
    """The configuration of ``options``, with its surface, workers and the search's conditions
    applied, and the conditions the design is judged in."""
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
        config = replace(config, budget=replace(config.budget, workers=options.workers))
    from reflector_opt.optimiser._conditions import search_conditions

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
        for given, flag in (
            (tolerance is not None, "--tolerances"),
            (options.pareto, "--pareto"),
            (options.drift_front, "--drift-front"),
            (options.starts > 1, "--starts"),
        ):
            if given:
                raise InputError(
                    f"--sensor: {len(parts)} parts, not with {flag}; choose the part first, "
                    f"then run {flag} with --sensor PART"
                )
    return parts


def prepare(options):
    """Resolve and check ``options`` before any work.

    Parameters
    ----------
    options : OptimiseOptions
        Checked against their declaration (:func:`reflector_opt.util._declared.checked`).

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
