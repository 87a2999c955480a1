"""The optimisation problem: objective, constraints and the evaluation of one candidate.

Objective (degrees, minimised): the worst-case Cramér–Rao resolution over the workspace,
``W = max(W_γ, W_α)`` with ``W_γ = max over poses of σ_γ`` and likewise for roll, times an
isotropy factor ``1 + w·|ln(W_γ/W_α)|`` that prefers equal pitch and roll resolution.

Constraints (each a value, a limit and a margin that is ≥ 0 when met):

============================  =====  ======================================================
name                          unit   requirement
============================  =====  ======================================================
``distance_margin_mm``        mm     every sensor's distance window lies inside its usable
                                     range with this margin at both ends
``axis_miss_fraction``        —      every optical axis meets the reflector at every pose
``sensor_envelope_mm``        mm     sensor radius + backing (package, strip) ≤ unit radius
``reflector_envelope_mm``     mm     the reflector sphere stays inside the unit radius
``bearing_clearance_mm``      mm     inner radius − bearing OD/2 ≥ the clearance
``wall_mm``                   mm     thinnest shell wall under the light spots ≥ min wall
``window_wall_mm``            mm     body wall above each sensor window ≥ min wall (the CAD's
                                     closed form, :func:`~.layout.window_wall_mm`)
``fold_fraction``             —      det J keeps one sign and never vanishes (no fold)
``separation_sigma``          σ_V    poses ≥ 1° apart give voltages ≥ k·σ_V apart
``printed_wall_mm``           mm     every wall of the printed parts ≥ min wall, by the rules
                                     the CAD export checks (:func:`reflector_opt.design.layout.
                                     plan_layout`); verification only (see below)
============================  =====  ======================================================

``printed_wall_mm`` is judged on the final design only (:meth:`Problem.check_printed`, about
1 s): the search and the polish steer by its cheap proxies, ``wall_mm`` (the shell under the
light spots), ``distance_margin_mm`` (the reflector's clearance in front of the sensors,
which sets the body wall behind each sensor channel), ``reflector_envelope_mm`` (the
swept space inside the unit) and ``window_wall_mm`` (exact: the wall above a sensor window
depends on the sensors alone); :data:`PRINTED_WALL_PROXIES` maps each printed wall to the
proxy whose tightening thickens it.

A candidate that breaks a constraint scores ``PENALTY + Σ violation/scale``: every feasible
design beats every infeasible one, and among infeasible ones the smaller violation wins
(Deb's feasibility rules, expressed as one number so that any minimiser can use it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from reflector_opt.analysis.metrics import evaluate_metrics
from reflector_opt.design import Mechanics, Noise, Workspace, default_design
from reflector_opt.design.layout import plan_layout, window_wall_mm
from reflector_opt.design.parts import CadParameters
from reflector_opt.model.sensors import SensorModel, get_preset
from reflector_opt.optimise.variables import (
    VARIABLES,
    build_design,
    default_bounds,
    embedded_sensor_models,
    resolve_bounds,
)
from reflector_opt.util.errors import InputError

__all__ = [
    "PENALTY",
    "PRINTED_WALL",
    "PRINTED_WALL_PROXIES",
    "Constraint",
    "Evaluation",
    "Problem",
    "objective_value",
]

#: Added to the violation of an infeasible candidate; far above any real resolution.
PENALTY = 1.0e6

#: A constraint missed by less than this (times its scale) is met: floating-point rounding,
#: e.g. a sensor placed exactly at the envelope's limit.
ROUNDING = 1e-9

#: Constraints that are smooth functions of the design at every pose (see
#: :meth:`Problem.pose_margins`).
SMOOTH_CONSTRAINTS = (
    "distance_margin_mm",
    "reflector_envelope_mm",
    "wall_mm",
    "window_wall_mm",
)

#: Name of the constraint on the walls of the printed parts.
PRINTED_WALL = "printed_wall_mm"

#: The printed walls (``"part: wall"``, see :func:`reflector_opt.design.layout.plan_layout`) that
#: depend on the design variables, and the smooth constraint whose tightening thickens each.
#: The other walls are fixed by the CAD parameters and the mechanics.
PRINTED_WALL_PROXIES = {
    "reflector: reflecting shell": "wall_mm",
    "body: wall behind a sensor channel": "distance_margin_mm",
    "body: wall outside the swept space": "reflector_envelope_mm",
    "body: wall between a tendon hole and the swept space": "reflector_envelope_mm",
    "body: wall above a sensor window": "window_wall_mm",
}

#: Violation assigned to a candidate that is not a valid design at all (e.g. a sensor inside
#: the sphere).
INVALID_VIOLATION = 100.0


@dataclass(frozen=True)
class Constraint:
    """One constraint evaluated at one candidate.

    Attributes
    ----------
    name : str
    value : float
        What the candidate achieves.
    limit : float
        The bound it must respect.
    upper : bool
        True if ``value <= limit`` is required, False for ``value >= limit``.
    unit : str
    scale : float
        Size of a violation that counts as 1 in the penalty.
    detail : str
        What the value measures, when the name does not say (e.g. which printed wall).
    """

    name: str
    value: float
    limit: float
    upper: bool
    unit: str
    scale: float
    detail: str = ""

    @property
    def margin(self):
        """How far inside the limit, in ``unit`` (negative: violated)."""
        return self.limit - self.value if self.upper else self.value - self.limit

    @property
    def met(self):
        """True when the constraint holds (to within rounding: ``ROUNDING`` × scale)."""
        return self.margin >= -ROUNDING * self.scale

    def to_dict(self):
        """JSON-ready record."""
        out = {
            "value": _json_number(self.value),
            "limit": self.limit,
            "sense": "<=" if self.upper else ">=",
            "margin": _json_number(self.margin),
            "unit": self.unit,
            "met": self.met,
        }
        if self.detail:
            out["detail"] = self.detail
        return out


def _tight(limit, upper, extra):
    """A limit moved inwards by ``extra``."""
    return limit - extra if upper else limit + extra


def _json_number(x):
    x = float(x)
    return x if math.isfinite(x) else None


def objective_value(metrics, isotropy_weight):
    """Worst-case resolution with the isotropy factor, degrees.

    ``max(W_γ, W_α) · (1 + w·|ln(W_γ/W_α)|)`` with W the worst-case Cramér–Rao 1σ pitch and
    roll resolution over the grid.

    Parameters
    ----------
    metrics : reflector_opt.analysis.metrics.DesignMetrics
    isotropy_weight : float
        Weight w ≥ 0 of the pitch/roll imbalance.

    Returns
    -------
    float
        Degrees; ``inf`` for a design without sensitivity.
    """
    wp, wr = metrics.worst_pitch_deg, metrics.worst_roll_deg
    if not (math.isfinite(wp) and math.isfinite(wr)):
        return math.inf
    return max(wp, wr) * (1.0 + isotropy_weight * abs(math.log(wp / wr)))


@dataclass(frozen=True)
class Evaluation:
    """One candidate evaluated on one pose grid.

    Attributes
    ----------
    values : dict or None
        The design variables, ``{name: value}`` (None for a design not built from them).
    design : reflector_opt.design.design.Design or None
        None if the values do not make a valid design (see ``error``).
    metrics : reflector_opt.analysis.metrics.DesignMetrics or None
    constraints : tuple of Constraint
    objective : float
        Degrees (``inf`` if not computable).
    error : str or None
        Why the values are not a valid design.
    printed_walls_mm : dict or None
        Every wall of the printed parts, ``{"part: wall": mm}``, once
        :meth:`Problem.check_printed` has run.
    """

    values: dict
    design: object
    metrics: object
    constraints: tuple
    objective: float
    error: str | None = None
    printed_walls_mm: dict | None = None

    @property
    def feasible(self):
        """True when the design is valid and meets every constraint."""
        return self.error is None and all(c.met for c in self.constraints)

    @property
    def violation(self):
        """Sum of the scaled constraint violations (0 when feasible)."""
        if self.error is not None:
            return INVALID_VIOLATION
        return float(sum(max(0.0, -c.margin) / c.scale for c in self.constraints if not c.met))

    @property
    def penalised(self):
        """The objective if feasible, else ``PENALTY + violation``: one number to minimise."""
        if self.feasible and math.isfinite(self.objective):
            return self.objective
        return PENALTY + self.violation

    def worst_constraint(self):
        """The most violated constraint (largest scaled violation), or None."""
        broken = [c for c in self.constraints if not c.met]
        return max(broken, key=lambda c: -c.margin / c.scale) if broken else None

    def describe_failure(self):
        """One line naming what makes the candidate infeasible."""
        if self.error is not None:
            return self.error
        c = self.worst_constraint()
        if c is None:
            return "feasible"
        sense = "at most" if c.upper else "at least"
        what = f"{c.name} ({c.detail})" if c.detail else c.name
        return (
            f"{what} is {c.value:.4g} {c.unit}, must be {sense} {c.limit:.4g} {c.unit} "
            f"(short by {-c.margin:.3g} {c.unit})"
        )

    def constraints_dict(self):
        """JSON-ready ``{name: record}``."""
        return {c.name: c.to_dict() for c in self.constraints}


@dataclass(frozen=True)
class Problem:
    """What to optimise and under which constraints.

    Parameters
    ----------
    sensor : reflector_opt.model.sensors.SensorModel
        The part used for both sensors (default the NJL5901R-2 preset).
    workspace : reflector_opt.design.components.Workspace
        Pitch and roll ranges; its step is the verification grid (0.1°).
    mechanics : reflector_opt.design.components.Mechanics
        The unit envelope, bearing and minimum printable wall.
    noise : reflector_opt.design.components.Noise
        Voltage noise and ADC of the read-out (σ_V of the Cramér–Rao bound).
    bounds : dict, optional
        ``{variable: (lower, upper)}`` replacing some defaults of
        :func:`~reflector_opt.optimise.variables.default_bounds`; equal bounds fix a
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
    cad : reflector_opt.design.parts.CadParameters
        Dimensions of the printed parts (clearances, band margin, sensor package …) whose
        walls :meth:`check_printed` judges; use the ones the design will be exported with.
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

    def __post_init__(self):
        for key in (
            "isotropy_weight",
            "distance_margin_mm",
            "bearing_clearance_mm",
            "sensor_backing_mm",
            "min_separation_sigma",
        ):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise InputError(f"{key}: expected a number, got {value!r}")
            if not math.isfinite(value) or value < 0:
                raise InputError(f"{key}: must be a finite number ≥ 0, got {value}")
        if not isinstance(self.cad, CadParameters):
            raise InputError(f"cad: expected CadParameters, got {type(self.cad).__name__}")
        defaults = default_bounds(
            self.sensor,
            self.mechanics,
            sensor_backing_mm=self.sensor_backing_mm,
            bearing_clearance_mm=self.bearing_clearance_mm,
        )
        object.__setattr__(self, "bounds", resolve_bounds(defaults, self.bounds))
        self._check_feasible_at_all()

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

    def _check_feasible_at_all(self):
        """Reject settings that no point inside the bounds can meet, naming the constraint."""
        lo, hi = self.sensor.range_mm
        if 2.0 * self.distance_margin_mm >= hi - lo:
            raise InputError(
                f"distance window: a margin of {self.distance_margin_mm} mm at both ends leaves "
                f"no room in the {self.sensor.name} usable range {lo}–{hi} mm"
            )
        limit = self.unit_radius_mm - self.sensor_backing_mm
        rho_lo, rho_hi = self.bounds["sensor_radius_mm"]
        if rho_lo > limit:
            raise InputError(
                f"sensor envelope: sensor_radius_mm ≥ {rho_lo} mm plus {self.sensor_backing_mm} mm "
                f"backing does not fit in the {self.mechanics.unit_diameter_mm} mm unit"
            )
        z_far = max(abs(v) for v in self.bounds["sensor_height_mm"])
        thickest = (
            math.hypot(min(rho_hi, limit), z_far)
            - (lo + self.distance_margin_mm)
            - self.inner_radius_mm
        )
        if thickest < self.mechanics.min_wall_mm:
            raise InputError(
                f"wall: with the sensors at most {min(rho_hi, limit):.3g} mm from the axis and "
                f"the reflector at least {lo + self.distance_margin_mm:.3g} mm from them, the "
                f"shell above the inner radius {self.inner_radius_mm:.3g} mm (bearing OD/2 + "
                f"clearance) is at most {thickest:.3g} mm thick, below the "
                f"{self.mechanics.min_wall_mm} mm minimum wall"
            )

    # -- candidates --

    def design(self, values, step_deg=None, *, checked=True):
        """The :class:`~reflector_opt.design.design.Design` at ``values``.

        Parameters
        ----------
        values : mapping of str to float
            Every design variable.
        step_deg : float, optional
            Grid step of the design's workspace (default: the problem's, 0.1°).
        checked : bool, optional
            False skips ``Design``'s construction checks (for search candidates, see
            :func:`~reflector_opt.optimise.variables.build_design`).
        """
        workspace = self.workspace
        if step_deg is not None:
            workspace = Workspace(workspace.pitch_deg, workspace.roll_deg, float(step_deg))
        return build_design(
            values,
            sensor=self.sensor,
            workspace=workspace,
            mechanics=self.mechanics,
            noise=self.noise,
            inner_radius_mm=self.inner_radius_mm,
            checked=checked,
        )

    def evaluate(
        self, values, step_deg=None, *, uniqueness_step_deg=None, tightening=None, checked=True
    ):
        """Objective and constraints at one point of the search, on one pose grid.

        Parameters
        ----------
        values : mapping of str to float
            Every design variable.
        step_deg : float, optional
            Pose grid step, degrees (default: the workspace's own).
        uniqueness_step_deg : float, optional
            Grid of the uniqueness check (see :func:`~.metrics.evaluate_metrics`).
        tightening : mapping of str to float, optional
            Extra margin demanded of named constraints (used to repair a design that fails
            on a finer grid than it was searched on).
        checked : bool, optional
            False for search candidates (see :meth:`design`).

        Returns
        -------
        Evaluation
        """
        values = {v.name: float(values[v.name]) for v in VARIABLES}
        try:
            design = self.design(values, step_deg, checked=checked)
        except InputError as exc:
            return Evaluation(values, None, None, (), math.inf, error=str(exc))
        return self.evaluate_design(
            design,
            step_deg,
            uniqueness_step_deg=uniqueness_step_deg,
            tightening=tightening,
            values=values,
        )

    def evaluate_design(
        self, design, step_deg=None, *, uniqueness_step_deg=None, tightening=None, values=None
    ):
        """Objective and constraints of any design under this problem's limits.

        Parameters
        ----------
        design : reflector_opt.design.design.Design
        step_deg, uniqueness_step_deg, tightening
            As for :meth:`evaluate`.
        values : dict, optional
            The design variables it was built from, kept in the result.

        Returns
        -------
        Evaluation
        """
        try:
            metrics = evaluate_metrics(design, step_deg, uniqueness_step_deg=uniqueness_step_deg)
        except InputError as exc:
            return Evaluation(values, design, None, (), math.inf, error=str(exc))
        constraints = self._constraints(design, metrics, tightening or {})
        return Evaluation(
            values, design, metrics, constraints, objective_value(metrics, self.isotropy_weight)
        )

    def _constraint_fields(self, design, metrics):
        """Every constraint as (name, values, limit, upper, unit, scale).

        ``values`` is an array over the grid (poses, and sensors) for the constraints that are
        smooth functions of the design at each pose, else a number.
        """
        mech = self.mechanics
        ranges = np.array([m.range_mm for m in design.models])
        d = metrics.distance_mm
        window = np.minimum(d - ranges[:, 0], ranges[:, 1] - d)
        sensor_reach = float(np.max(np.hypot(*design.positions_mm[:, :2].T)))
        return (
            ("distance_margin_mm", window, self.distance_margin_mm, False, "mm", 1.0),
            ("axis_miss_fraction", metrics.axis_miss_fraction, 0.0, True, "", 0.1),
            (
                "sensor_envelope_mm",
                sensor_reach + self.sensor_backing_mm,
                self.unit_radius_mm,
                True,
                "mm",
                1.0,
            ),
            ("reflector_envelope_mm", metrics.reach_mm, self.unit_radius_mm, True, "mm", 1.0),
            (
                "bearing_clearance_mm",
                design.reflector.inner_radius_mm - 0.5 * mech.bearing_od_mm,
                self.bearing_clearance_mm,
                False,
                "mm",
                1.0,
            ),
            ("wall_mm", metrics.wall_mm, mech.min_wall_mm, False, "mm", 1.0),
            (
                "window_wall_mm",
                window_wall_mm(design, self.cad),
                mech.min_wall_mm,
                False,
                "mm",
                1.0,
            ),
            ("fold_fraction", metrics.fold_fraction, 0.0, True, "", 0.1),
            (
                "separation_sigma",
                metrics.min_separation_sigma,
                self.min_separation_sigma,
                False,
                "σ_V",
                max(self.min_separation_sigma, 1.0),
            ),
        )

    def _constraints(self, design, metrics, tightening):
        out = []
        for name, values, limit, upper, unit, scale in self._constraint_fields(design, metrics):
            v = np.asarray(values, dtype=float)
            finite = v[np.isfinite(v)] if v.ndim else v
            if v.ndim and finite.size == 0:
                worst = math.inf if upper else -math.inf
            elif v.ndim:
                worst = float(finite.max() if upper else finite.min())
            else:
                worst = float(v)
            out.append(
                Constraint(
                    name, worst, _tight(limit, upper, tightening.get(name, 0.0)), upper, unit, scale
                )
            )
        return tuple(out)

    def check_printed(self, evaluation):
        """Add the walls of the printed parts to an evaluation, by the CAD export's rules.

        The layout of both parts (:func:`reflector_opt.design.layout.plan_layout`, the function the
        CAD export builds from) gives every designed wall; the thinnest becomes the
        constraint ``printed_wall_mm`` (≥ ``mechanics.min_wall_mm``), its ``detail`` naming
        the wall. A design the parts cannot be laid out for at all becomes invalid, with the
        layout's reason.

        Parameters
        ----------
        evaluation : Evaluation
            A valid candidate, usually on the workspace grid.

        Returns
        -------
        Evaluation
            With ``printed_walls_mm`` filled in (unchanged if ``evaluation`` is not valid).
        """
        if evaluation.error is not None or evaluation.design is None:
            return evaluation
        try:
            layout = plan_layout(evaluation.design, self.cad)
        except InputError as exc:
            return replace(evaluation, error=f"printed parts: {exc}")
        walls = {f"reflector: {k}": float(v) for k, v in layout.reflector_walls_mm.items()}
        walls |= {f"body: {k}": float(v) for k, v in layout.body_walls_mm.items()}
        thinnest = min(walls, key=walls.get)
        constraint = Constraint(
            PRINTED_WALL,
            walls[thinnest],
            float(self.mechanics.min_wall_mm),
            False,
            "mm",
            1.0,
            detail=thinnest,
        )
        return replace(
            evaluation,
            constraints=(*evaluation.constraints, constraint),
            printed_walls_mm=walls,
        )

    def pose_margins(self, evaluation, tightening=None):
        """Per-pose margins of the smooth constraints and the per-pose resolution.

        For a local, gradient-based polish: the worst case over poses is a maximum, which has
        kinks, but each pose's value is a smooth function of the design.

        Parameters
        ----------
        evaluation : Evaluation
            A valid candidate.
        tightening : mapping of str to float, optional

        Returns
        -------
        (numpy.ndarray, numpy.ndarray)
            1σ pitch and roll resolution at every pose (degrees), and the margins (scaled by
            each constraint's scale; ≥ 0 when met) of :data:`SMOOTH_CONSTRAINTS` at every pose,
            flattened; a pose where an axis misses the reflector counts as a violation of 1.
        """
        tightening = tightening or {}
        metrics = evaluation.metrics
        margins = []
        for name, values, limit, upper, _, scale in self._constraint_fields(
            evaluation.design, metrics
        ):
            if name in SMOOTH_CONSTRAINTS:
                limit = _tight(limit, upper, tightening.get(name, 0.0))
                m = (limit - values if upper else values - limit) / scale
                margins.append(np.where(np.isfinite(m), m, -1.0).ravel())
        resolution = np.concatenate(
            [metrics.resolution_pitch_deg.ravel(), metrics.resolution_roll_deg.ravel()]
        )
        return resolution, np.concatenate(margins)

    def baseline_design(self):
        """The built-in default geometry under this problem's part, workspace, envelope and noise.

        Returns
        -------
        reflector_opt.design.design.Design
            Raises :class:`~reflector_opt.util.errors.InputError` if that geometry is not valid
            here (e.g. a sensor inside the sphere).
        """
        base = default_design()
        sensors = tuple(
            type(s)(s.name, self.sensor.name, s.position_mm, s.axis, s.detector_direction)
            for s in base.sensors
        )
        return base.replace(
            sensors=sensors,
            workspace=self.workspace,
            mechanics=self.mechanics,
            noise=self.noise,
            sensor_models=embedded_sensor_models(self.sensor),
        )
