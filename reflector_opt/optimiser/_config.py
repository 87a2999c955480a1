"""TOML configuration of the optimiser (``reflector-opt optimise --config FILE.toml``).

Every section and key is optional; what is left out keeps its built-in default. Unknown
sections or keys are an error (a typo must not be silently ignored). See docs/optimiser.md
for the reference and examples/optimise.toml for a complete file.

.. code-block:: toml

    [sensor]
    model = "NJL5901R-2"          # a preset (reflector_opt.model._sensors.PRESETS)
    range_mm = [0.5, 3.0]         # optional: the usable distance range of that part

    [workspace]                   # reflector_opt.design._components.Workspace
    [mechanics]                   # reflector_opt.design._components.Mechanics
    [noise]                       # reflector_opt.design._components.Noise
    [bounds]                      # variable = [min, max]; min == max fixes it
    [objective]                   # isotropy_weight
    [constraints]                 # distance_margin_mm, bearing_clearance_mm, ...
    [search]                      # seed and reflector_opt.optimiser.SearchBudget fields
    [pareto]                      # margins_mm = [...], drift_fractions = [...]
    [robust]                      # coverage, max_rounds: used with --tolerances
    [cad]                         # reflector_opt.design._parts.CadParameters fields: the
                                  # printed parts whose walls the verification checks
    [surface]
    material = "white-sla-resin"  # a preset (reflector_opt.model._surface.MATERIALS)
    reflectance = 0.9             # optional: override the preset's ρ
    specular_fraction = 0.05      # optional: override the preset's f
    specular_fraction_range = [0.0, 0.2]  # optional: optimise the worst case over f

    [conditions]                  # optional: optimise the worst-case total error in these
    temperature_range_k = 5.0     # operating conditions (the keys of docs/conditions.md)
"""

from dataclasses import dataclass, field, replace

import msgspec

from reflector_opt.design import Mechanics, Noise, Workspace
from reflector_opt.design._conditions import parse_conditions
from reflector_opt.design._parts import CadParameters
from reflector_opt.model._surface import get_material
from reflector_opt.optimiser import Problem, SearchBudget
from reflector_opt.optimiser._drift_front import DEFAULT_DRIFT_FRACTIONS
from reflector_opt.optimiser._pareto import DEFAULT_MARGINS_MM
from reflector_opt.optimiser._robust import RobustOptions
from reflector_opt.optimiser._schema import OptimiseDocument
from reflector_opt.util import _schema as schema
from reflector_opt.util._errors import InputError, in_section
from reflector_opt.util._fileio import read_config


@dataclass(frozen=True)
class OptimiseConfig:
    """Everything ``reflector-opt optimise`` needs.

    Attributes
    ----------
    problem : reflector_opt.optimiser.Problem
    budget : reflector_opt.optimiser.SearchBudget
    seed : int
    pareto_margins_mm : tuple of float
        Distance-margin levels of the Pareto front, mm.
    robust : reflector_opt.optimiser._robust.RobustOptions
        Coverage and most rounds of the robust optimisation (``--tolerances``).
    drift_fractions : tuple of float
        Drift limits of the drift front (``--drift-front``), as fractions of the white-noise
        optimum's drift.

    The ``[conditions]`` table, if any, is the problem's ``conditions``.
    """

    problem: Problem = field(default_factory=Problem)
    budget: SearchBudget = field(default_factory=SearchBudget)
    seed: int = 0
    pareto_margins_mm: tuple = DEFAULT_MARGINS_MM
    robust: RobustOptions = field(default_factory=RobustOptions)
    drift_fractions: tuple = DEFAULT_DRIFT_FRACTIONS


def _sensor(table):
    """The ``[sensor]`` table's model: a preset or any part of the shipped catalogue."""
    from reflector_opt.model._catalogue import sensor_model

    try:
        model = sensor_model(table.model)
    except InputError as exc:  # the catalogue's message has no key
        raise InputError(f"sensor.model: {exc}") from None
    if table.range_mm is not None:
        lo, hi = table.range_mm
        if lo > hi:
            raise InputError(f"sensor.range_mm: min {lo} is greater than max {hi}")
        model = model.with_(range_mm=(lo, hi))
    return model


def _surface(table):
    """The material from a ``[surface]`` table, with the preset's ρ and f overridden."""
    try:
        material = get_material(table.material)
    except InputError as exc:  # the catalogue's message has no key
        raise InputError(f"surface.material: {exc}") from None
    changes = {
        key: getattr(table, key)
        for key in ("reflectance", "specular_fraction")
        if getattr(table, key) is not None
    }
    if changes:
        material = replace(material, name=f"{material.name} (modified)", **changes)
    return material


def _conditions(table):
    """The ``[conditions]`` table checked as a conditions file's (its units too)."""
    return parse_conditions({"conditions": table.to_dict()})


def _fields(table, *drop):
    return {k: v for k, v in msgspec.structs.asdict(table).items() if k not in drop}


def parse_config(data):
    """Build an :class:`OptimiseConfig` from a parsed TOML document.

    The document is checked against :class:`~reflector_opt.optimiser._schema.OptimiseDocument`
    (types, ranges, unknown keys); the objects built from it check the rest.

    Parameters
    ----------
    data : dict
        As returned by :func:`tomllib.loads`.

    Returns
    -------
    OptimiseConfig
        Raises :class:`~reflector_opt.util._errors.InputError` naming the section and key at fault,
        or the constraint that no design can meet.
    """
    document = schema.convert(data, OptimiseDocument, toml=True)
    fraction_range = document.surface.specular_fraction_range
    problem = Problem(
        sensor=_sensor(document.sensor),
        workspace=Workspace.from_dict(_fields(document.workspace)),
        mechanics=Mechanics.from_dict(msgspec.to_builtins(document.mechanics)),
        noise=Noise.from_dict(_fields(document.noise)),
        bounds={name: tuple(pair) for name, pair in document.bounds.items()},
        cad=CadParameters.from_table(document.cad),
        surface=_surface(document.surface),
        specular_fraction_range=None if fraction_range is None else tuple(fraction_range),
        conditions=_conditions(document.conditions) if "conditions" in data else None,
        **_fields(document.objective),
        **_fields(document.constraints),
    )
    with in_section("robust"):
        robust = RobustOptions(**_fields(document.robust))
    return OptimiseConfig(
        problem=problem,
        budget=SearchBudget(**_fields(document.search, "seed")),
        seed=document.search.seed,
        pareto_margins_mm=tuple(sorted(document.pareto.margins_mm)),
        robust=robust,
        drift_fractions=tuple(sorted(document.pareto.drift_fractions, reverse=True)),
    )


def load_config(path):
    """Read and check an optimiser config file.

    Parameters
    ----------
    path : str or pathlib.Path
        A TOML file.

    Returns
    -------
    OptimiseConfig
    """
    return read_config(path, parse_config)
