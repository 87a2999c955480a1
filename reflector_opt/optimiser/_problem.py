"""The optimisation problem: what to optimise, within which bounds and under which limits.

A :class:`Problem` declares the part, workspace, envelope and noise, the bounds of the design
variables (:mod:`~reflector_opt.optimiser._variables`) and the limits of the constraints, and
refuses settings that no design within the bounds can meet. What is done with it lives beside
it, and its methods bind each job to the problem:

* :mod:`~reflector_opt.optimiser._candidates` — the design at a point of the search, and the
  built-in baseline (:meth:`Problem.design`, :meth:`Problem.baseline_design`);
* :mod:`~reflector_opt.optimiser._evaluation` — the objective and the evaluation of one
  candidate (:meth:`Problem.evaluate`, :meth:`Problem.evaluate_design`);
* :mod:`~reflector_opt.optimiser._constraints` — the constraints, their margins and their
  per-pose margins for the polish (:meth:`Problem.pose_margins`);
* :mod:`~reflector_opt.optimiser._printed_walls` — the walls of the printed parts, checked on the
  final design (:meth:`Problem.check_printed`);
* :mod:`~reflector_opt.optimiser._conditions` — in operating conditions, the error budget as
  the objective, and the drift limit (through :meth:`Problem.evaluate`).
"""

import math
from dataclasses import dataclass, field
from typing import Annotated

from msgspec import Meta

import reflector_opt.optimiser._candidates as _candidates
import reflector_opt.optimiser._constraints as _constraints
import reflector_opt.optimiser._evaluation as _evaluation
import reflector_opt.optimiser._printed_walls as _printed
from reflector_opt.design import Mechanics, Noise, Workspace
from reflector_opt.design._bearings import check_tilt
from reflector_opt.design._conditions import Conditions
from reflector_opt.design._parts import CadParameters
from reflector_opt.model._sensors import SensorModel, get_preset
from reflector_opt.model._surface import DEFAULT_MATERIAL, Material, get_material
from reflector_opt.optimiser._variables import default_bounds, resolve_bounds
from reflector_opt.util import _schema as schema
from reflector_opt.util._display import Summarised, fmt, span
from reflector_opt.util._errors import InputError, NoDesignError
from reflector_opt.util._limits import MAX_LENGTH_MM


@dataclass(frozen=True, repr=False)
class Problem(Summarised):
    """What to optimise and under which constraints.

    Parameters
    ----------
    sensor : reflector_opt.model._sensors.SensorModel
        The part used for both sensors (default the NJL5901R-2 preset).
    workspace : reflector_opt.design._components.Workspace
        Pitch and roll ranges; its step is the verification grid (0.1°).
    mechanics : reflector_opt.design._components.Mechanics
        The unit envelope, bearing and minimum printable wall.
    noise : reflector_opt.design._components.Noise
        Voltage noise and ADC of the read-out (σ_V of the Cramér–Rao bound).
    bounds : dict, optional
        ``{variable: (lower, upper)}`` replacing some defaults of
        :func:`~reflector_opt.optimiser._variables.default_bounds`; equal bounds fix a
        variable. After construction it holds the bounds of every variable.
    isotropy_weight : float
        Weight of the pitch/roll imbalance in the objective (≥ 0).
    distance_margin_mm : float
        Required margin between each sensor's distance window and its usable range, mm.
    bearing_clearance_mm : float
        Radial clearance between the shell's inner surface and the bearing's outer ring, mm.
    sensor_backing_mm : float
        Radial room behind a sensor's emitting face (package and flexible strip), mm.
    min_separation_sigma : float
        Required voltage separation of poses ≥ 1° apart, in σ_V.
    cad : reflector_opt.design._parts.CadParameters
        Dimensions of the printed parts (clearances, band margin, sensor package …) whose
        walls :meth:`check_printed` judges; use the ones the design will be exported with.
    surface : reflector_opt.model._surface.Material
        The reflector's surface (reflectance and specular fraction) the design is optimised
        for and written with; default the ``white-sla-resin`` material.
    specular_fraction_range : (float, float) or None
        Optimise the worst case over this interval of the specular fraction f (its ends and
        middle) instead of ``surface.specular_fraction`` alone; None (default) for the
        stated surface only.
    conditions : reflector_opt.design._conditions.Conditions or None
        Operating conditions: the objective becomes the worst-case total error in them
        (:mod:`~reflector_opt.optimiser._conditions`); None (default) for the worst-case 1σ
        resolution in white noise.
    drift_limit_deg : float or None
        Most common drift allowed, degrees per 1 % change of the light path (RMS over the
        workspace, the worse angle): one more constraint, for the Pareto front of
        :mod:`~reflector_opt.optimiser._drift_front`; None (default) for none.
    """

    sensor: SensorModel = field(default_factory=lambda: get_preset("NJL5901R-2"))
    workspace: Workspace = field(default_factory=Workspace)
    mechanics: Mechanics = field(default_factory=Mechanics)
    noise: Noise = field(default_factory=Noise)
    bounds: dict = field(default_factory=dict)
    isotropy_weight: float = 0.25
    distance_margin_mm: float = 0.1
    bearing_clearance_mm: float = 0.5
    sensor_backing_mm: float = 1.0
    min_separation_sigma: float = 3.0
    cad: CadParameters = field(default_factory=CadParameters)
    surface: Material = field(default_factory=lambda: get_material(DEFAULT_MATERIAL))
    specular_fraction_range: tuple | None = None
    conditions: Conditions | None = None
    drift_limit_deg: float | None = None

    def __post_init__(self):
        _check_settings(self)
        defaults = default_bounds(
            self.sensor,
            self.mechanics,
            sensor_backing_mm=self.sensor_backing_mm,
            bearing_clearance_mm=self.bearing_clearance_mm,
        )
        object.__setattr__(self, "bounds", resolve_bounds(defaults, self.bounds))
        _check_feasible_at_all(self)

    # -- derived quantities --

    @property
    def unit_radius_mm(self):
        """Radius of the unit envelope, mm."""
        return 0.5 * self.mechanics.unit_diameter_mm

    @property
    def inner_radius_mm(self):
        """Inner radius of the reflector shell: bearing OD/2 plus the clearance, mm."""
        return 0.5 * self.mechanics.bearing_od_mm + self.bearing_clearance_mm

    @property
    def search_bounds(self):
        """Bounds actually searched: the sensor radius is capped by the envelope."""
        bounds = dict(self.bounds)
        lo, hi = bounds["sensor_radius_mm"]
        bounds["sensor_radius_mm"] = (lo, min(hi, self.unit_radius_mm - self.sensor_backing_mm))
        return bounds

    @property
    def free_names(self):
        """Variables with lower < upper, in declaration order."""
        return tuple(n for n, (lo, hi) in self.search_bounds.items() if lo < hi)

    @property
    def fixed_values(self):
        """``{name: value}`` of the variables held fixed (lower == upper)."""
        return {n: lo for n, (lo, hi) in self.search_bounds.items() if lo == hi}

    @property
    def specular_fractions(self):
        """The specular fractions f whose worst case the search minimises."""
        if self.specular_fraction_range is None:
            return (self.surface.specular_fraction,)
        lo, hi = self.specular_fraction_range
        return (lo, 0.5 * (lo + hi), hi) if hi > lo else (lo,)

    # -- the jobs done with a problem (see the module's docstring), bound to it --

    def design(self, values, step_deg=None, *, checked=True):
        """:func:`~reflector_opt.optimiser._candidates.candidate_design` under this problem."""
        return _candidates.candidate_design(self, values, step_deg, checked=checked)

    def baseline_design(self):
        """:func:`~reflector_opt.optimiser._candidates.baseline_design` under this problem."""
        return _candidates.baseline_design(self)

    def evaluate(
        self, values, step_deg=None, *, uniqueness_step_deg=None, tightening=None, checked=True
    ):
        """:func:`~reflector_opt.optimiser._evaluation.evaluate` under this problem."""
        return _evaluation.evaluate(
            self,
            values,
            step_deg,
            uniqueness_step_deg=uniqueness_step_deg,
            tightening=tightening,
            checked=checked,
        )

    def evaluate_design(
        self, design, step_deg=None, *, uniqueness_step_deg=None, tightening=None, values=None
    ):
        """:func:`~reflector_opt.optimiser._evaluation.evaluate_design` under this problem."""
        return _evaluation.evaluate_design(
            self,
            design,
            step_deg,
            uniqueness_step_deg=uniqueness_step_deg,
            tightening=tightening,
            values=values,
        )

    def pose_margins(self, evaluation, tightening=None):
        """:func:`~reflector_opt.optimiser._constraints.pose_margins` under this problem."""
        return _constraints.pose_margins(self, evaluation, tightening)

    def check_printed(self, evaluation):
        """:func:`~reflector_opt.optimiser._printed_walls.check_printed` under this problem."""
        return _printed.check_printed(self, evaluation)

    # -- display (equality is the dataclass's, field by field) --

    def _summary(self):
        """Title and (label, value) rows: the part, the envelope, the variables, the limits."""
        sensor, surface, w = self.sensor, self.surface, self.workspace
        m, n = self.mechanics, self.noise
        free, fixed = self.free_names, self.fixed_values
        bounds = self.search_bounds
        if self.specular_fraction_range is None:
            f_text = f"specular fraction {fmt(surface.specular_fraction)}"
        else:
            f_text = f"worst case over specular fraction {span(*self.specular_fraction_range)}"
        rows = [
            ("sensor", f"{sensor.name}, usable {span(*sensor.range_mm, unit='mm')}"),
            ("surface", f"{surface.name}: reflectance {fmt(surface.reflectance)}, {f_text}"),
            (
                "workspace",
                f"pitch {span(*w.pitch_deg, unit='°')}, roll {span(*w.roll_deg, unit='°')}, "
                f"verified on a {fmt(w.step_deg, unit='°')} grid",
            ),
            (
                "unit",
                f"diameter {fmt(m.unit_diameter_mm, unit='mm')}, bearing "
                f"{fmt(m.bearing_bore_mm)}/{fmt(m.bearing_od_mm, unit='mm')}, wall ≥ "
                f"{fmt(m.min_wall_mm, unit='mm')}",
            ),
            ("noise", f"σ_V {fmt(1e3 * n.sigma_v, unit='mV')}, {n.adc_bits}-bit ADC"),
            ("free variables", ", ".join(f"{k} {span(*bounds[k])}" for k in free)),
        ]
        if fixed:
            rows.append(("fixed", ", ".join(f"{k} = {fmt(v)}" for k, v in fixed.items())))
        rows.append(
            (
                "limits",
                f"distance margin {fmt(self.distance_margin_mm, unit='mm')}, bearing clearance "
                f"{fmt(self.bearing_clearance_mm, unit='mm')}, sensor backing "
                f"{fmt(self.sensor_backing_mm, unit='mm')}, separation ≥ "
                f"{fmt(self.min_separation_sigma)} σ_V",
            )
        )
        if self.conditions is None:
            judged = "the worst 1σ resolution"
        else:
            c = self.conditions
            judged = (
                f"the worst total error in use (±{fmt(c.temperature_range_k, unit='K')}, "
                f"{c.drive} drive)"
            )
            rows.append(("conditions", ", ".join(f"{k} {v}" for k, v in c.to_dict().items())))
        if self.drift_limit_deg is not None:
            rows.append(("drift limit", f"{fmt(self.drift_limit_deg, unit='°')} per 1 %"))
        title = (
            f"Problem: {judged} (imbalance weight {fmt(self.isotropy_weight)}) "
            f"over {len(free)} free variables"
        )
        return title, rows


Distance = Annotated[float, Meta(ge=0, le=MAX_LENGTH_MM, description="a distance, mm")]
Weight = Annotated[float, Meta(ge=0, le=1e6)]
Fraction = Annotated[float, Meta(ge=0, le=1)]


class ObjectiveTable(schema.Table):
    """``[objective]``."""

    # Each key's range is declared here once: Problem is checked against it too.

    isotropy_weight: Annotated[Weight, Meta(description="weight of the anisotropy term")] = (
        Problem.isotropy_weight
    )


class ConstraintsTable(schema.Table):
    """``[constraints]``: the limits a design must meet."""

    distance_margin_mm: Distance = Problem.distance_margin_mm
    bearing_clearance_mm: Distance = Problem.bearing_clearance_mm
    sensor_backing_mm: Distance = Problem.sensor_backing_mm
    min_separation_sigma: Annotated[Weight, Meta(description="in noise σ")] = (
        Problem.min_separation_sigma
    )


class SurfaceTable(schema.Table):
    """``[surface]``: the reflector's material."""

    material: Annotated[str, Meta(description="a material preset")] = DEFAULT_MATERIAL
    reflectance: (
        Annotated[float, Meta(gt=0, le=1, description="override the preset's ρ")] | None
    ) = None
    specular_fraction: Fraction | None = None
    specular_fraction_range: (
        Annotated[list[Fraction], Meta(min_length=2, max_length=2, description="[min, max] of f")]
        | None
    ) = None


def _check_settings(problem):
    """Check the weight, the limits and the interval of f against ``[objective]``,
    ``[constraints]`` and ``[surface]`` (:class:`ObjectiveTable`, :class:`ConstraintsTable`,
    :class:`SurfaceTable`), the one place their ranges are stated, and refuse a ``cad`` or
    ``surface`` of another type."""
    for table in (ObjectiveTable, ConstraintsTable):
        schema.convert({k: getattr(problem, k) for k in table.__struct_fields__}, table)
    if problem.sensor_backing_mm >= problem.unit_radius_mm:  # the default bounds come from it
        raise InputError(
            f"sensor_backing_mm: {problem.sensor_backing_mm} mm of room behind each sensor "
            f"leaves none for the sensors in the {problem.mechanics.unit_diameter_mm} mm unit"
        )
    if not isinstance(problem.cad, CadParameters):
        raise InputError(f"cad: expected CadParameters, got {type(problem.cad).__name__}")
    if not isinstance(problem.surface, Material):
        raise InputError(f"surface: expected a Material, got {type(problem.surface).__name__}")
    _check_operating(problem)
    check_tilt(problem.workspace, problem.mechanics)
    interval = problem.specular_fraction_range
    if interval is not None:
        table = schema.convert({"specular_fraction_range": interval}, SurfaceTable)
        lo, hi = table.specular_fraction_range
        if lo > hi:
            raise InputError(
                f"specular_fraction_range: expected 0 ≤ min ≤ max ≤ 1, got [{lo}, {hi}]"
            )
        object.__setattr__(problem, "specular_fraction_range", (lo, hi))


def _check_operating(problem):
    """Reject ``conditions`` of another type or a drift limit that is not a number > 0."""
    if problem.conditions is not None and not isinstance(problem.conditions, Conditions):
        raise InputError(
            f"conditions: expected Conditions, got {type(problem.conditions).__name__}"
        )
    limit = problem.drift_limit_deg
    if limit is not None:
        if isinstance(limit, bool) or not isinstance(limit, int | float):
            raise InputError(f"drift_limit_deg: expected a number, got {limit!r}")
        if not (math.isfinite(limit) and limit > 0):
            raise InputError(f"drift_limit_deg: must be a finite number > 0, got {limit}")


def _check_feasible_at_all(problem):
    """Reject settings that no point inside the bounds can meet, naming the constraint."""
    lo, hi = problem.sensor.range_mm
    margin = problem.distance_margin_mm
    if 2.0 * margin >= hi - lo:
        raise NoDesignError(
            f"distance window: a margin of {margin} mm at both ends leaves "
            f"no room in the {problem.sensor.name} usable range {lo}–{hi} mm"
        )
    mech = problem.mechanics
    limit = problem.unit_radius_mm - problem.sensor_backing_mm
    rho_lo, rho_hi = problem.bounds["sensor_radius_mm"]
    if rho_lo > limit:
        raise NoDesignError(
            f"sensor envelope: sensor_radius_mm ≥ {rho_lo} mm plus {problem.sensor_backing_mm} "
            f"mm backing does not fit in the {mech.unit_diameter_mm} mm unit"
        )
    z_far = max(abs(v) for v in problem.bounds["sensor_height_mm"])
    inner = problem.inner_radius_mm
    thickest = math.hypot(min(rho_hi, limit), z_far) - (lo + margin) - inner
    if thickest < mech.min_wall_mm:
        raise NoDesignError(
            f"wall: with the sensors at most {min(rho_hi, limit):.3g} mm from the axis and "
            f"the reflector at least {lo + margin:.3g} mm from them, the "
            f"shell above the inner radius {inner:.3g} mm (bearing OD/2 + "
            f"clearance) is at most {thickest:.3g} mm thick, below the "
            f"{mech.min_wall_mm} mm minimum wall"
        )
