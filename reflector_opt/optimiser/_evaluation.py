"""The evaluation of one candidate: metrics, constraints and the objective, as one number.

Objective (degrees, minimised): the worst-case Cramér–Rao resolution over the workspace,
``W = max(W_γ, W_α)`` with ``W_γ = max over poses of σ_γ`` and likewise for roll, times an
isotropy factor ``1 + w·|ln(W_γ/W_α)|`` that prefers equal pitch and roll resolution.

With operating conditions (``Problem.conditions``) the objective is instead the worst-case
total error in them, with the same isotropy factor (:mod:`~reflector_opt.optimiser._conditions`);
with a drift limit (``Problem.drift_limit_deg``) the common drift is one more constraint.
:func:`in_conditions` adds both to an evaluation, for either path of the search.

A candidate that breaks a constraint (:mod:`~reflector_opt.optimiser._constraints`) scores
``PENALTY + Σ violation/scale``: every feasible design beats every infeasible one, and among
infeasible ones the smaller violation wins (Deb's feasibility rules, expressed as one number
so that any minimiser can use it).
"""

import math
from dataclasses import dataclass, replace

from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.design._design import Design
from reflector_opt.optimiser._candidates import surface_variants
from reflector_opt.optimiser._conditions import DRIFT_CONSTRAINT, drift_constraint, worst_budget
from reflector_opt.optimiser._constraints import worst_case_constraints
from reflector_opt.optimiser._variables import VARIABLES, values_from_vector
from reflector_opt.util._errors import InputError

#: Added to the violation of an infeasible candidate; far above any real resolution.
PENALTY = 1.0e6

#: Violation assigned to a candidate that is not a valid design at all (e.g. a sensor inside
#: the sphere).
INVALID_VIOLATION = 100.0


def objective_value(metrics, isotropy_weight):
    """Worst-case resolution with the isotropy factor, degrees.

    ``max(W_γ, W_α) · (1 + w·|ln(W_γ/W_α)|)`` with W the worst-case Cramér–Rao 1σ pitch and
    roll resolution over the grid.

    Parameters
    ----------
    metrics : reflector_opt.analysis._metrics.DesignMetrics
    isotropy_weight : float
        Weight w ≥ 0 of the pitch/roll imbalance.

    Returns
    -------
    float
        Degrees; ``inf`` for a design without sensitivity.
    """
    return isotropic_worst_deg(metrics.worst_pitch_deg, metrics.worst_roll_deg, isotropy_weight)


def isotropic_worst_deg(pitch_deg, roll_deg, isotropy_weight):
    """``max(W_γ, W_α) · (1 + w·|ln(W_γ/W_α)|)``: a worst case with the isotropy factor.

    Parameters
    ----------
    pitch_deg, roll_deg : float
        The worst case of each angle over the workspace, degrees.
    isotropy_weight : float
        Weight w ≥ 0 of the pitch/roll imbalance.

    Returns
    -------
    float
        Degrees; ``inf`` if either is not finite.
    """
    if not (math.isfinite(pitch_deg) and math.isfinite(roll_deg)):
        return math.inf
    return max(pitch_deg, roll_deg) * (1.0 + isotropy_weight * abs(math.log(pitch_deg / roll_deg)))


@dataclass(frozen=True)
class Evaluation:
    """One candidate evaluated on one pose grid.

    Attributes
    ----------
    values : dict or None
        The design variables, ``{name: value}`` (None for a design not built from them).
    design : reflector_opt.design._design.Design or None
        None if the values do not make a valid design (see ``error``).
    metrics : reflector_opt.analysis._metrics.DesignMetrics or None
    constraints : tuple of Constraint
    objective : float
        Degrees (``inf`` if not computable): the worst-case 1σ resolution with the isotropy
        factor or, in operating conditions, the worst-case total error with it (see
        ``budget``).
    error : str or None
        Why the values are not a valid design.
    printed_walls_mm : dict or None
        Every wall of the printed parts, ``{"part: wall": mm}``, once
        :func:`~reflector_opt.optimiser._printed_walls.check_printed` has run.
    budget : reflector_opt.analysis._budget.ErrorBudget or None
        In operating conditions, the error budget the objective comes from (the worst
        surface's, on the judging stage's budget grid); None without conditions, and for a
        search candidate that breaks a constraint (whose score does not read the objective:
        its ``objective`` is then the white-noise one).
    """

    values: dict
    design: object
    metrics: object
    constraints: tuple
    objective: float
    error: str | None = None
    printed_walls_mm: dict | None = None
    budget: object = None

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


def evaluate(
    problem, values, step_deg=None, *, uniqueness_step_deg=None, tightening=None, checked=True
):
    """Objective and constraints at one point of the search, on one pose grid.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
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
        False for search candidates (see :meth:`~reflector_opt.optimiser._problem.Problem.design`).

    Returns
    -------
    Evaluation
    """
    values = {v.name: float(values[v.name]) for v in VARIABLES}
    try:
        design = problem.design(values, step_deg, checked=checked)
    except InputError as exc:
        return Evaluation(values, None, None, (), math.inf, error=str(exc))
    return evaluate_design(
        problem,
        design,
        step_deg,
        uniqueness_step_deg=uniqueness_step_deg,
        tightening=tightening,
        values=values,
    )


def evaluate_design(
    problem, design, step_deg=None, *, uniqueness_step_deg=None, tightening=None, values=None
):
    """Objective and constraints of any design under a problem's limits.

    With a ``specular_fraction_range`` the design is evaluated at each of the problem's
    :attr:`~reflector_opt.optimiser._problem.Problem.specular_fractions` and the worst of
    them (the largest penalised objective) is returned, with the design as given.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
    design : reflector_opt.design._design.Design
    step_deg, uniqueness_step_deg, tightening
        As for :func:`evaluate`.
    values : dict, optional
        The design variables it was built from, kept in the result.

    Returns
    -------
    Evaluation
    """
    worst = None
    for variant in surface_variants(problem, design):
        try:
            metrics = evaluate_metrics(variant, step_deg, uniqueness_step_deg=uniqueness_step_deg)
        except InputError as exc:
            return Evaluation(values, design, None, (), math.inf, error=str(exc))
        constraints = worst_case_constraints(problem, variant, metrics, tightening or {})
        result = Evaluation(
            values, design, metrics, constraints, objective_value(metrics, problem.isotropy_weight)
        )
        if worst is None or result.penalised > worst.penalised:
            worst = result
    return in_conditions(problem, worst, step_deg, design=design, tightening=tightening)


def in_conditions(problem, evaluation, step_deg, *, design=None, tightening=None, always=True):
    """The evaluation with the problem's drift limit and its objective in its conditions.

    Without ``conditions`` and ``drift_limit_deg`` (the default problem), or for a candidate
    that is not a valid, sensitive design, ``evaluation`` itself. Otherwise: the drift
    constraint (:func:`~reflector_opt.optimiser._conditions.drift_constraint`) is added if
    the problem sets a limit and the evaluation does not hold it yet; then, with conditions,
    the objective becomes the worst-case total error with the isotropy factor, the largest
    over the problem's specular fractions, and ``budget`` the budget that gives it — for
    every candidate if ``always``, else only for a feasible one.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
    evaluation : Evaluation
    step_deg : float or None
        The grid the evaluation was judged on, degrees (None: the design's workspace's).
    design : reflector_opt.design._design.Design, optional
        The candidate's design; built from ``evaluation.values`` on that grid if not given
        and ``evaluation.design`` is not one (the fused path's placement).
    tightening : mapping of str to float, optional
        Extra margin demanded of named constraints.
    always : bool, optional
        False leaves an infeasible candidate's objective alone (the search's score does not
        read it).

    Returns
    -------
    Evaluation
        With ``error`` set (not a valid design) if the budget's poses make the sensors
        touch the sphere.
    """
    wanted = problem.conditions is not None or problem.drift_limit_deg is not None
    metrics = evaluation.metrics
    if not wanted or evaluation.error is not None or metrics is None or not metrics.sensitive:
        return evaluation
    step = metrics.step_deg if step_deg is None else float(step_deg)
    try:
        return _operating(problem, evaluation, step, design, tightening or {}, always)
    except InputError as exc:  # e.g. the budget's poses (stencil, joint play) collide
        return replace(evaluation, objective=math.inf, error=str(exc))


def _operating(problem, evaluation, step, design, tightening, always):
    """:func:`in_conditions` of a valid, sensitive candidate."""
    if design is None:
        design = evaluation.design
        if not isinstance(design, Design):
            design = problem.design(evaluation.values, step, checked=False)
    constraints = evaluation.constraints
    held = {c.name for c in constraints}
    if problem.drift_limit_deg is not None and DRIFT_CONSTRAINT not in held:
        drift = drift_constraint(problem, design, step, tightening)
        evaluation = replace(evaluation, constraints=(*constraints, drift))
    if problem.conditions is None or evaluation.budget is not None:
        return evaluation
    if not (always or evaluation.feasible):
        return evaluation
    weight = problem.isotropy_weight
    objective, budget = worst_budget(
        problem, design, step, lambda p, r: isotropic_worst_deg(p, r, weight)
    )
    return replace(evaluation, objective=objective, budget=budget)


class PenalisedObjective:
    """``x -> Evaluation.penalised`` over the free variables; picklable for worker processes.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
    step_deg : float
        Pose grid step, degrees.
    """

    def __init__(self, problem, step_deg):
        self.problem = problem
        self.step_deg = float(step_deg)
        self.names = problem.free_names
        self.fixed = problem.fixed_values

    def values(self, x):
        """``{name: value}`` for every variable at the free-variable vector ``x``."""
        return values_from_vector(self.names, x, self.fixed)

    def evaluate(self, x):
        """The full :class:`Evaluation` at ``x``."""
        return self.evaluate_values(self.values(x))

    def evaluate_values(self, values, tightening=None):
        """The full :class:`Evaluation` at ``values`` (every design variable)."""
        return self.problem.evaluate(values, self.step_deg, tightening=tightening, checked=False)

    def __call__(self, x):
        return self.evaluate(x).penalised
