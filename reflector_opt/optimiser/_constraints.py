"""The optimiser's constraints: each a value, a limit and a margin that is ≥ 0 when met.

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
                                     the CAD export checks (:func:`reflector_opt.design._layout.
                                     plan_layout`); verification only
                                     (:mod:`~reflector_opt.optimiser._printed_walls`)
============================  =====  ======================================================

The limits come from a :class:`~reflector_opt.optimiser._problem.Problem`; the values from a
design and its :class:`~reflector_opt.analysis._metrics.DesignMetrics`. A limit can be
*tightened* (moved inwards by an extra margin) to repair a design that fails on a finer grid
than it was searched on.
"""

import math
from dataclasses import dataclass

import numpy as np

from reflector_opt.design._layout import window_wall_mm
from reflector_opt.util._fileio import json_number

#: A constraint missed by less than this (times its scale) is met: floating-point rounding,
#: e.g. a sensor placed exactly at the envelope's limit.
ROUNDING = 1e-9

#: Constraints that are smooth functions of the design at every pose (see
#: :func:`pose_margins`).
SMOOTH_CONSTRAINTS = (
    "distance_margin_mm",
    "reflector_envelope_mm",
    "wall_mm",
    "window_wall_mm",
)


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
            "value": json_number(self.value),
            "limit": self.limit,
            "sense": "<=" if self.upper else ">=",
            "margin": json_number(self.margin),
            "unit": self.unit,
            "met": self.met,
        }
        if self.detail:
            out["detail"] = self.detail
        return out


def _tight(limit, upper, extra):
    """A limit moved inwards by ``extra``."""
    return limit - extra if upper else limit + extra


def constraint_fields(problem, design, metrics):
    """Every constraint (but the printed walls) as (name, values, limit, upper, unit, scale).

    ``values`` is an array over the grid (poses, and sensors) for the constraints that are
    smooth functions of the design at each pose, else a number.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
        The limits.
    design : reflector_opt.design._design.Design
    metrics : reflector_opt.analysis._metrics.DesignMetrics
        The design's metrics on some pose grid.

    Returns
    -------
    tuple of tuple
    """
    wall, radius = problem.mechanics.min_wall_mm, problem.unit_radius_mm
    sigma = problem.min_separation_sigma
    ranges = np.array([m.range_mm for m in design.models])
    d = metrics.distance_mm
    window = np.minimum(d - ranges[:, 0], ranges[:, 1] - d)
    sensor_reach = float(np.max(np.hypot(*design.positions_mm[:, :2].T)))
    clearance = design.reflector.inner_radius_mm - 0.5 * problem.mechanics.bearing_od_mm
    # name, values, limit, upper, unit, scale
    return (
        ("distance_margin_mm", window, problem.distance_margin_mm, False, "mm", 1.0),
        ("axis_miss_fraction", metrics.axis_miss_fraction, 0.0, True, "", 0.1),
        ("sensor_envelope_mm", sensor_reach + problem.sensor_backing_mm, radius, True, "mm", 1.0),
        ("reflector_envelope_mm", metrics.reach_mm, radius, True, "mm", 1.0),
        ("bearing_clearance_mm", clearance, problem.bearing_clearance_mm, False, "mm", 1.0),
        ("wall_mm", metrics.wall_mm, wall, False, "mm", 1.0),
        ("window_wall_mm", window_wall_mm(design, problem.cad), wall, False, "mm", 1.0),
        ("fold_fraction", metrics.fold_fraction, 0.0, True, "", 0.1),
        ("separation_sigma", metrics.min_separation_sigma, sigma, False, "σ_V", max(sigma, 1.0)),
    )


def worst_case_constraints(problem, design, metrics, tightening):
    """Each constraint at its worst over the grid (non-finite values ignored).

    Parameters
    ----------
    problem, design, metrics
        As for :func:`constraint_fields`.
    tightening : mapping of str to float
        Extra margin demanded of named constraints.

    Returns
    -------
    tuple of Constraint
    """
    out = []
    for name, values, limit, upper, unit, scale in constraint_fields(problem, design, metrics):
        v = np.asarray(values, dtype=float)
        finite = v[np.isfinite(v)] if v.ndim else v
        if v.ndim and finite.size == 0:
            worst = math.inf if upper else -math.inf
        elif v.ndim:
            worst = float(finite.max() if upper else finite.min())
        else:
            worst = float(v)
        limit = _tight(limit, upper, tightening.get(name, 0.0))
        out.append(Constraint(name, worst, limit, upper, unit, scale))
    return tuple(out)


def pose_margins(problem, evaluation, tightening=None):
    """Per-pose margins of the smooth constraints and the per-pose resolution.

    For a local, gradient-based polish: the worst case over poses is a maximum, which has
    kinks, but each pose's value is a smooth function of the design.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
    evaluation : reflector_opt.optimiser._evaluation.Evaluation
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
    for name, values, limit, upper, _, scale in constraint_fields(
        problem, evaluation.design, metrics
    ):
        if name in SMOOTH_CONSTRAINTS:
            limit = _tight(limit, upper, tightening.get(name, 0.0))
            m = (limit - values if upper else values - limit) / scale
            margins.append(np.where(np.isfinite(m), m, -1.0).ravel())
    resolution = np.concatenate(
        [metrics.resolution_pitch_deg.ravel(), metrics.resolution_roll_deg.ravel()]
    )
    return resolution, np.concatenate(margins)
