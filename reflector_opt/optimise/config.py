"""TOML configuration of the optimiser (``reflector-opt optimise --config FILE.toml``).

Every section and key is optional; what is left out keeps its built-in default. Unknown
sections or keys are an error (a typo must not be silently ignored). See docs/optimiser.md
for the reference and examples/optimise.toml for a complete file.

.. code-block:: toml

    [sensor]
    model = "NJL5901R-2"          # a preset (reflector_opt.model.sensors.PRESETS)
    range_mm = [0.5, 3.0]         # optional: the usable distance range of that part

    [workspace]                   # reflector_opt.design.components.Workspace
    [mechanics]                   # reflector_opt.design.components.Mechanics
    [noise]                       # reflector_opt.design.components.Noise
    [bounds]                      # variable = [min, max]; min == max fixes it
    [objective]                   # isotropy_weight
    [constraints]                 # distance_margin_mm, bearing_clearance_mm, ...
    [search]                      # seed and reflector_opt.optimise.SearchBudget fields
    [pareto]                      # margins_mm = [...]
    [robust]                      # coverage, max_rounds: used with --tolerances
    [cad]                         # reflector_opt.design.parts.CadParameters fields: the
                                  # printed parts whose walls the verification checks
    [surface]
    material = "white-sla-resin"  # a preset (reflector_opt.model.surface.MATERIALS)
    reflectance = 0.9             # optional: override the preset's ρ
    specular_fraction = 0.05      # optional: override the preset's f
    specular_fraction_range = [0.0, 0.2]  # optional: optimise the worst case over f
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace

from reflector_opt.design import Mechanics, Noise, Workspace
from reflector_opt.design.parts import CadParameters
from reflector_opt.model.sensors import get_preset
from reflector_opt.model.surface import DEFAULT_MATERIAL, get_material
from reflector_opt.optimise import Problem, SearchBudget
from reflector_opt.optimise.pareto import DEFAULT_MARGINS_MM
from reflector_opt.optimise.robust import RobustOptions
from reflector_opt.util.errors import InputError
from reflector_opt.util.fileio import read_toml

__all__ = ["OptimiseConfig", "load_config", "parse_config"]

_SECTIONS = (
    "sensor",
    "workspace",
    "mechanics",
    "noise",
    "bounds",
    "objective",
    "constraints",
    "search",
    "pareto",
    "robust",
    "cad",
    "surface",
)
_CONSTRAINT_KEYS = (
    "distance_margin_mm",
    "bearing_clearance_mm",
    "sensor_backing_mm",
    "min_separation_sigma",
)


@dataclass(frozen=True)
class OptimiseConfig:
    """Everything ``reflector-opt optimise`` needs.

    Attributes
    ----------
    problem : reflector_opt.optimise.Problem
    budget : reflector_opt.optimise.SearchBudget
    seed : int
    pareto_margins_mm : tuple of float
        Distance-margin levels of the Pareto front, mm.
    robust : reflector_opt.optimise.robust.RobustOptions
        Coverage and most rounds of the robust optimisation (``--tolerances``).
    """

    problem: Problem = field(default_factory=Problem)
    budget: SearchBudget = field(default_factory=SearchBudget)
    seed: int = 0
    pareto_margins_mm: tuple = DEFAULT_MARGINS_MM
    robust: RobustOptions = field(default_factory=RobustOptions)


def _table(data, key, allowed):
    block = data.get(key, {})
    if not isinstance(block, dict):
        raise InputError(f"[{key}]: expected a table")
    unknown = sorted(set(block) - set(allowed))
    if unknown:
        raise InputError(
            f"[{key}]: unknown key(s) {', '.join(unknown)}; allowed: {', '.join(allowed)}"
        )
    return block


def _sensor(block):
    name = block.get("model", "NJL5901R-2")
    if not isinstance(name, str):
        raise InputError(f"sensor.model: expected a preset name, got {name!r}")
    model = get_preset(name)
    if "range_mm" in block:
        value = block["range_mm"]
        if (
            not isinstance(value, list)
            or len(value) != 2
            or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
        ):
            raise InputError(f"sensor.range_mm: expected [min, max] in mm, got {value!r}")
        lo, hi = (float(v) for v in value)
        if lo > hi:
            raise InputError(f"sensor.range_mm: min {lo} is greater than max {hi}")
        model = model.with_(range_mm=(lo, hi))
    return model


def _surface(block):
    """The material and the interval of f from a ``[surface]`` table."""
    name = block.get("material", DEFAULT_MATERIAL)
    if not isinstance(name, str):
        raise InputError(f"surface.material: expected a preset name, got {name!r}")
    material = get_material(name)
    changes = {}
    for key in ("reflectance", "specular_fraction"):
        if key in block:
            value = block[key]
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise InputError(f"surface.{key}: expected a number, got {value!r}")
            if not 0.0 <= value <= 1.0 or (key == "reflectance" and value == 0.0):
                raise InputError(f"surface.{key}: must be in {_UNIT_RANGES[key]}, got {value}")
            changes[key] = float(value)
    interval = block.get("specular_fraction_range")
    if interval is not None and (
        not isinstance(interval, list)
        or len(interval) != 2
        or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in interval)
    ):
        raise InputError(
            f"surface.specular_fraction_range: expected [min, max] in 0–1, got {interval!r}"
        )
    if changes:
        material = replace(material, name=f"{material.name} (modified)", **changes)
    return material, None if interval is None else tuple(interval)


#: Most margins of a Pareto front (each costs one optimisation).
MAX_PARETO_POINTS = 100

_UNIT_RANGES = {"reflectance": "(0, 1]", "specular_fraction": "[0, 1]"}


def _bounds(block):
    """Shapes checked here; names and ranges by the problem (with hints for derived names)."""
    if not isinstance(block, dict):
        raise InputError("[bounds]: expected a table")
    for name, pair in block.items():
        if not isinstance(pair, list) or len(pair) != 2:
            raise InputError(f"bounds.{name}: expected [min, max], got {pair!r}")
        for v in pair:
            if isinstance(v, bool) or not isinstance(v, int | float):
                raise InputError(f"bounds.{name}: expected numbers, got {pair!r}")
    return {name: tuple(pair) for name, pair in block.items()}


def _margins(block):
    value = block.get("margins_mm", list(DEFAULT_MARGINS_MM))
    if (
        not isinstance(value, list)
        or not value
        or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
    ):
        raise InputError(f"pareto.margins_mm: expected a list of numbers in mm, got {value!r}")
    if any(v < 0 for v in value):
        raise InputError("pareto.margins_mm: margins must not be negative")
    if len(value) > MAX_PARETO_POINTS:
        raise InputError(
            f"pareto.margins_mm: at most {MAX_PARETO_POINTS} margins (one optimisation each), "
            f"got {len(value)}"
        )
    return tuple(sorted(float(v) for v in value))


def parse_config(data):
    """Build an :class:`OptimiseConfig` from a parsed TOML document.

    Parameters
    ----------
    data : dict
        As returned by :func:`tomllib.loads`.

    Returns
    -------
    OptimiseConfig
        Raises :class:`~reflector_opt.util.errors.InputError` naming the section and key at fault,
        or the constraint that no design can meet.
    """
    unknown = sorted(set(data) - set(_SECTIONS))
    if unknown:
        raise InputError(
            f"unknown section(s) {', '.join(unknown)}; allowed: {', '.join(_SECTIONS)}"
        )
    sensor = _sensor(_table(data, "sensor", ("model", "range_mm")))
    ws = _table(data, "workspace", ("pitch_deg", "roll_deg", "step_deg"))
    workspace = Workspace.from_dict({**Workspace().to_dict(), **ws})
    mechanics = Mechanics.from_dict(
        _table(data, "mechanics", tuple(f.name for f in fields(Mechanics)))
    )
    noise = Noise.from_dict(_table(data, "noise", ("sigma_v", "adc_bits", "vref")))
    objective = _table(data, "objective", ("isotropy_weight",))
    constraints = _table(data, "constraints", _CONSTRAINT_KEYS)
    search = dict(_table(data, "search", ("seed", *(f.name for f in fields(SearchBudget)))))
    pareto = _table(data, "pareto", ("margins_mm",))
    robust = _table(data, "robust", tuple(f.name for f in fields(RobustOptions)))
    surface, fraction_range = _surface(
        _table(
            data,
            "surface",
            ("material", "reflectance", "specular_fraction", "specular_fraction_range"),
        )
    )

    seed = search.pop("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError(f"search.seed: expected a whole number ≥ 0, got {seed!r}")
    problem = Problem(
        sensor=sensor,
        workspace=workspace,
        mechanics=mechanics,
        noise=noise,
        bounds=_bounds(data.get("bounds", {})),
        cad=CadParameters.from_dict(data.get("cad", {}), where="cad"),
        surface=surface,
        specular_fraction_range=fraction_range,
        **objective,
        **constraints,
    )
    try:
        robust = RobustOptions(**robust)
    except InputError as exc:
        raise InputError(f"robust.{exc}") from None
    return OptimiseConfig(
        problem=problem,
        budget=SearchBudget(**search),
        seed=seed,
        pareto_margins_mm=_margins(pareto),
        robust=robust,
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
    data = read_toml(path)
    try:
        return parse_config(data)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
