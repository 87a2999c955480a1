"""The local polish: SLSQP on the epigraph form of the worst case, from a few starts.

The global search only has to find the right basin: the polish finds its bottom. The worst
case over poses is a maximum, which has kinks, but the resolution and the smooth constraints'
margins at each pose (:func:`~reflector_opt.optimiser._constraints.pose_margins`) are smooth
functions of the design, so a gradient method converges where a simplex on the worst case
stalls. It starts from the search's best member, then from the polished point's image with the
geometry mirrored in the unit's xy-plane (see
:data:`~reflector_opt.optimiser._variables.Z_MIRRORED`: the objective has two similar basins and
the population settles in one of them) and, when the pair's azimuth or across offset is
searched, from the mirror-symmetric layouts of both; the best point is kept.
"""

import numpy as np
from scipy.optimize import minimize

from reflector_opt.optimiser._conditions import (
    DRIFT_CONSTRAINT,
    pose_totals,
    separation_margins,
    steered_constraints,
)
from reflector_opt.optimiser._evaluation import in_conditions
from reflector_opt.optimiser._fused_objective import search_objective
from reflector_opt.optimiser._variables import (
    forward_steps,
    symmetric_layout,
    values_from_vector,
    z_mirror,
)

#: Forward-difference step of the polish, in units of each variable's range.
POLISH_STEP = 1e-6

#: The polish keeps every scaled margin at least this far inside its limit, so that a
#: constraint active at the optimum is met, not missed by rounding.
POLISH_CUSHION = 1e-6


class _FieldsAt:
    """Per-pose resolution and constraint margins at one normalised point; picklable."""

    def __init__(self, problem, lower, upper, step_deg, tightening):
        self.problem = problem
        self.lower, self.span = lower, upper - lower
        self.judge = search_objective(problem, step_deg)
        self.tightening = tightening

    def __call__(self, u):
        x = np.clip(self.lower + u * self.span, self.lower, self.lower + self.span)
        values = values_from_vector(self.problem.free_names, x, self.problem.fixed_values)
        e = self.judge.evaluate_values(values, self.tightening)
        if e.metrics is None or not e.metrics.sensitive:
            return None
        fields = self.problem.pose_margins(e, self.tightening)
        return operating_fields(self.problem, e, self.judge.step_deg, fields, self.tightening)


def operating_fields(problem, evaluation, step_deg, fields, tightening):
    """The polish's fields of a candidate: what it minimises at each pose and its margins.

    Without conditions, the 1σ resolution at each pose; in conditions, the total error of
    the budget at each pose of its grid, pitch then roll
    (:func:`~reflector_opt.optimiser._conditions.pose_totals`). In conditions or with a drift
    limit, the uniqueness margin at every pose
    (:func:`~reflector_opt.optimiser._conditions.separation_margins`) and the drift limit's
    scaled margin join the per-pose margins. Every margin less :data:`POLISH_CUSHION`.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
    evaluation : reflector_opt.optimiser._evaluation.Evaluation
        A valid, sensitive candidate judged on ``step_deg``.
    step_deg : float
        Its pose grid, degrees.
    fields : (numpy.ndarray, numpy.ndarray)
        Its resolution and margins at every pose
        (:func:`~reflector_opt.optimiser._constraints.pose_margins`).
    tightening : mapping of str to float

    Returns
    -------
    (numpy.ndarray, numpy.ndarray) or None
        None if the budget finds no valid design there (its poses collide).
    """
    resolution, margins = fields
    if not steered_constraints(problem):
        return resolution, margins - POLISH_CUSHION
    e = in_conditions(problem, evaluation, step_deg, tightening=tightening)
    if e.error is not None:
        return None
    if problem.conditions is not None:
        totals = pose_totals(e.budget)
        resolution = np.concatenate([totals[..., 0].ravel(), totals[..., 1].ravel()])
    drift = [c.margin / c.scale for c in e.constraints if c.name == DRIFT_CONSTRAINT]
    separation = separation_margins(problem, e.metrics, tightening)
    return resolution, np.concatenate([margins, separation, drift]) - POLISH_CUSHION


class _PoseFields:
    """:class:`_FieldsAt` cached per point; :meth:`prefetch` computes several with ``map_``."""

    def __init__(self, problem, lower, upper, step_deg, tightening, map_=map):
        self.at = _FieldsAt(problem, lower, upper, step_deg, tightening)
        self.map = map_
        self.cache = {}
        self.points = {}

    def __call__(self, u):
        key = u.tobytes()
        if key not in self.cache:
            self.cache[key] = self.at(u)
            self.points[key] = np.array(u, dtype=float)
        return self.cache[key]

    def rank(self, key, walls):
        """(violation, worst scaled resolution) of a computed point: its largest shortfall of
        a margin (the walls' linear model's too, when given; ``inf`` where the point makes
        no valid design), then the worst of its resolutions."""
        f = self.cache[key]
        if f is None:
            return (np.inf, np.inf)
        margins = f[1] if walls is None else np.append(f[1], walls.margins(self.points[key]))
        return (max(0.0, -float(margins.min(initial=np.inf))), float(f[0].max()))

    def best(self, u, walls):
        """``u`` if it meets every margin, else the computed point that misses them least,
        then has the least worst resolution (Deb's rules, as the search's penalty)."""
        key = u.tobytes()
        if key in self.cache and self.rank(key, walls)[0] == 0.0:
            return u
        return self.points[min(self.cache, key=lambda k: self.rank(k, walls))]

    def prefetch(self, points):
        """Compute the fields at ``points`` not yet cached, side by side where ``map_`` runs
        them on worker processes; the same values as one at a time."""
        missing = {u.tobytes(): u for u in points if u.tobytes() not in self.cache}
        for key, fields in zip(missing, self.map(self.at, list(missing.values())), strict=True):
            self.cache[key] = fields
            self.points[key] = np.array(missing[key], dtype=float)


def _epigraph_constraints(fields, start, walls):
    """SLSQP's inequality constraints of the epigraph form, with their Jacobians.

    ``z = (u, t)``: ``t − σ(p)/scale ≥ 0`` for each resolution at each pose (scaled by the
    worst at the start), every smooth margin ≥ 0, and the walls' linear model ≥ its limits
    when given; the Jacobian by forward differences of :data:`POLISH_STEP`, the points of
    one step computed together (:meth:`_PoseFields.prefetch`).
    """
    scale = float(start[0].max())
    n_res, n_all = start[0].size, start[0].size + start[1].size

    def constraints(z):
        f = fields(z[:-1])
        if f is None:
            return np.full(n_all, -1.0)
        return np.concatenate([z[-1] - f[0] / scale, f[1]])

    def constraints_jacobian(z):
        u, c0 = z[:-1], constraints(z)
        jac = np.zeros((n_all, z.size))
        steps, moved = forward_steps(u, POLISH_STEP)
        points = [np.append(uk, z[-1]) for uk in moved]
        fields.prefetch(moved)
        for k, (du, point) in enumerate(zip(steps, points, strict=True)):
            jac[:, k] = (constraints(point) - c0) / du
        jac[:n_res, -1] = 1.0
        return jac

    out = [{"type": "ineq", "fun": constraints, "jac": constraints_jacobian}]
    if walls is not None:
        wall_jacobian = np.hstack([walls.slope, np.zeros((walls.slope.shape[0], 1))])
        out.append(
            {
                "type": "ineq",
                "fun": lambda z: walls.margins(z[:-1]) - POLISH_CUSHION,
                "jac": lambda z: wall_jacobian,
            }
        )
    return out


def polish(problem, x0, lower, upper, step_deg, maxiter, tightening=None, walls=None, map_=map):
    """SLSQP on the epigraph form of the worst case, from x0.

    ``minimise t  subject to  σ_γ(p) ≤ t, σ_α(p) ≤ t  and  m_k(p) ≥ 0  at every pose p``,
    with m_k the margins of the smooth constraints (distance window, reflector envelope,
    wall); in operating conditions σ is the total error of the budget at each pose, and a
    drift limit adds its margin (:func:`operating_fields`). Each is a smooth function of the
    design, so a gradient method converges to the local optimum precisely where a simplex on
    the worst case stalls at its kinks. The variables are scaled to [0, 1]; derivatives are
    forward differences, one evaluation per free variable.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
    x0, lower, upper : numpy.ndarray
        Start and bounds of the free variables.
    step_deg : float
        Pose grid, degrees.
    maxiter : int
        Most SLSQP iterations.
    tightening : mapping of str to float, optional
        Extra margin demanded of named smooth constraints.
    walls : reflector_opt.optimiser._printed_walls.LinearWalls, optional
        The printed walls near x0 as linear constraints (each ≥ its limit).
    map_ : callable, optional
        ``map_(function, points)``, ordered like the builtin ``map``: the forward differences
        of each step are computed with it (e.g. a worker pool's ``map``), with the same
        result.

    Returns
    -------
    (numpy.ndarray, int)
        The point reached and the evaluations used. SLSQP can stop outside its constraints
        (a line search that finds no descent, the iteration limit); the point returned is
        then the one of those the polish computed that misses its margins least, then has
        the least worst resolution (:meth:`_PoseFields.best`), never a point it knows to
        miss them more: its start at worst.
    """
    fields = _PoseFields(problem, lower, upper, step_deg, tightening or {}, map_)
    u0 = (np.asarray(x0, dtype=float) - lower) / (upper - lower)
    start = fields(u0)
    if start is None or maxiter == 0:
        return np.asarray(x0, dtype=float), len(fields.cache)
    last = np.eye(u0.size + 1)[-1]
    res = minimize(
        lambda z: z[-1],
        np.append(u0, 1.0),
        jac=lambda z: last,
        method="SLSQP",
        bounds=[(0.0, 1.0)] * u0.size + [(0.0, None)],
        constraints=_epigraph_constraints(fields, start, walls),
        options={"maxiter": maxiter, "ftol": 1e-10},
    )
    u = fields.best(res.x[:-1], walls)
    return np.clip(lower + u * (upper - lower), lower, upper), len(fields.cache)


def other_basins(problem, x, lower, upper):
    """x's z-mirror image and, if the pair's symmetry is searched, the mirror-symmetric
    layouts of x and of its image; each clipped to the bounds, without x or repeats."""
    names = problem.free_names
    values = values_from_vector(names, x, problem.fixed_values)
    layouts = [values, z_mirror(values)]
    if {"sensor_azimuth_deg", "centre_across_mm"} & set(names):
        layouts += [symmetric_layout(v) for v in layouts]
    starts = [np.asarray(x, dtype=float)]
    for v in layouts[1:]:
        start = np.clip([v[n] for n in names], lower, upper)
        if not any(np.array_equal(start, s) for s in starts):
            starts.append(start)
    return starts[1:]


def polish_from_starts(problem, x, lower, upper, budget, map_=map):
    """Polish x, then polish from the other basins' images of the polished point.

    The image of a converged point lies near the bottom of the other basin, which the image
    of a rough search result may not. Returns the best of x and every polished point (judged
    on the polish grid) and the evaluations used; ``map_`` as for :func:`polish`.

    Returns
    -------
    (numpy.ndarray, int)
    """
    step, maxiter = budget.polish_step_deg, budget.polish_maxiter
    first, used = polish(problem, x, lower, upper, step, maxiter, map_=map_)
    candidates = [np.asarray(x, dtype=float), first]
    for start in other_basins(problem, first, lower, upper):
        point, n = polish(problem, start, lower, upper, step, maxiter, map_=map_)
        candidates.append(point)
        used += n
    scores = list(map_(search_objective(problem, step), candidates))
    return candidates[int(np.argmin(scores))], used + len(candidates)
