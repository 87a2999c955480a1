"""What a user loses on a printed unit: the angle error after calibration and the margins.

A print correction is worth what it gives the user of the next batch, not how close the
printed distances come to the drawing's. Each printed unit (a built design and its read-out,
:func:`reflector_opt.asbuilt._batchforecast.predicted_units`) is scored with the fast model on a
pose grid over the workspace (:func:`unit_figures`):

* **angle error after calibration**: the worst-case Cramér–Rao 1σ resolution (the larger of
  pitch and roll), the floor a per-unit calibration reaches
  (:func:`reflector_opt.analysis._resolution.resolution_over_poses`, the unit's own gain, σ_V with
  quantisation);
* **drift sensitivity**: the worst-case angle shift of a 1 % change of the light path
  common to the sensors, δθ = (JᵀJ)⁻¹Jᵀ δV with δV = −0.01·(Vcc − V)
  (:func:`reflector_opt.analysis._budget.angle_shift_deg`, as
  :func:`~reflector_opt.analysis._budget.drift_sensitivity`);
* **distance window**: per sensor, ``min(d_min − lo, hi − d_max)`` of the Eq 3 distance over
  the workspace against the usable range (:func:`~reflector_opt.analysis._metrics.distance_window`);
* **distance to the response peak**: per sensor, ``d_min − d_peak``, d_peak the peak of its
  flat-mirror curve (:func:`reflector_opt.model._catalogue_fit.flat_peak`): nearer than the
  peak the output folds back and two distances give one voltage;
* **clearance**: the unit's radius less the reflector sphere's largest reach from the axis
  (:func:`~reflector_opt.analysis._metrics.reflector_reach_mm`).

:func:`loss_deg` makes one number of them, in degrees: the angle error plus the drift
sensitivity plus :data:`PENALTY_DEG_PER_MM` times every margin's shortfall below its target
``max(0, target − margin)``, the target being the drawing's own margin or
:data:`REQUIRED_MARGIN_MM` (the optimiser's default distance margin), whichever is smaller.
A margin above its target is not lost: a print that leaves a sensor farther inside its
window than drawn loses nothing, one that takes it near or out of the window does.
"""

from dataclasses import dataclass
from functools import cache

import numpy as np

from reflector_opt.analysis._budget import angle_shift_deg
from reflector_opt.analysis._jacobian import jacobian_from_stencil, stencil_poses
from reflector_opt.analysis._metrics import distance_window, reflector_reach_mm
from reflector_opt.analysis._resolution import resolution_over_poses
from reflector_opt.model._catalogue_fit import flat_peak
from reflector_opt.model._forward import respond

#: Cost of a margin's shortfall, degrees per mm: 10 µm of margin lost weigh 0.01°, about 6 %
#: of the default design's worst-case resolution.
PENALTY_DEG_PER_MM = 1.0

#: The margin below which margin counts as lost, mm (the optimiser's default distance margin).
REQUIRED_MARGIN_MM = 0.1

#: Pose-grid step of the figures, degrees (21 × 21 poses over ±15°).
STEP_DEG = 1.5

#: The relative change of the light path of the drift sensitivity (1 %).
DRIFT_CHANGE = 0.01


@dataclass(frozen=True)
class UnitFigures:
    """A printed unit's figures over its workspace.

    Attributes
    ----------
    angle_deg : float
        Worst-case Cramér–Rao 1σ resolution, the larger of pitch and roll, degrees.
    drift_deg : float
        Worst-case angle shift of a 1 % common light-path change, degrees.
    window_mm : tuple of float
        Per sensor, the distance window's margin to the usable range, mm.
    peak_mm : tuple of float
        Per sensor, the smallest distance less the response peak's distance, mm.
    clearance_mm : float
        The unit's radius less the reflector's largest reach from the axis, mm.
    """

    angle_deg: float
    drift_deg: float
    window_mm: tuple
    peak_mm: tuple
    clearance_mm: float

    def margins(self):
        """Every margin, in order: the windows, the peaks, the clearance (mm)."""
        return np.array([*self.window_mm, *self.peak_mm, self.clearance_mm])

    def to_dict(self):
        """JSON-ready dict."""
        return {
            "angle_deg": float(self.angle_deg),
            "drift_deg": float(self.drift_deg),
            "window_mm": [float(x) for x in self.window_mm],
            "peak_mm": [float(x) for x in self.peak_mm],
            "clearance_mm": float(self.clearance_mm),
        }


@cache
def _peak_mm(model):
    return flat_peak(model, "mirror")[0]


def unit_figures(built, mismatch=None, step_deg=STEP_DEG):
    """The figures of one printed unit (module docstring), fast model.

    Parameters
    ----------
    built : reflector_opt.design._design.Design
        The unit as printed.
    mismatch : reflector_opt.model._noise.Mismatch, optional
        Its read-out (gain, offset); None: nominal.
    step_deg : float
        Pose-grid step, degrees.

    Returns
    -------
    UnitFigures
    """
    pitch, roll = np.broadcast_arrays(*built.workspace.grid(step_deg))
    response = respond(built, *stencil_poses(pitch, roll))
    raw = response.volts if mismatch is None else mismatch.apply(response.volts)
    volts, jac = jacobian_from_stencil(raw)
    supply = np.array([m.supply_v for m in built.models])
    drift = angle_shift_deg(jac, -DRIFT_CHANGE * (supply - volts))
    distance = response.distance_mm[0]
    ranges = [m.range_mm for m in built.models]
    d_min, _, window = distance_window(distance, ranges)
    peak = d_min - np.array([_peak_mm(m) for m in built.models])
    r = built.reflector
    reach = reflector_reach_mm(r.centre_mm, r.radius_mm, pitch, roll)
    return UnitFigures(
        angle_deg=resolution_over_poses(jac, built.noise.total_sigma_v).worst,
        drift_deg=float(np.max(np.abs(drift))),
        window_mm=tuple(window.tolist()),
        peak_mm=tuple(peak.tolist()),
        clearance_mm=float(0.5 * built.mechanics.unit_diameter_mm - np.max(reach)),
    )


def loss_deg(figures, targets, penalty_deg_per_mm=PENALTY_DEG_PER_MM):
    """One unit's loss: angle error + drift sensitivity + penalty × margins' shortfall.

    ``L = θ_worst + θ_drift + P · Σ_k max(0, min(drawn_k, m_req) − margin_k)``, degrees, with
    m_req = :data:`REQUIRED_MARGIN_MM`.

    Parameters
    ----------
    figures : UnitFigures
        The unit's figures.
    targets : UnitFigures
        The drawing's own (its margins, capped at :data:`REQUIRED_MARGIN_MM`, are the
        targets).
    penalty_deg_per_mm : float
        P, degrees per mm (default :data:`PENALTY_DEG_PER_MM`).

    Returns
    -------
    float
        Degrees (inf where the unit has no sensitivity somewhere).
    """
    target = np.minimum(targets.margins(), REQUIRED_MARGIN_MM)
    shortfall = np.clip(target - figures.margins(), 0.0, None)
    return figures.angle_deg + figures.drift_deg + penalty_deg_per_mm * float(shortfall.sum())


def batch_figures(units, step_deg=STEP_DEG):
    """A batch's figures: the angle errors' mean and largest, each margin's smallest.

    Parameters
    ----------
    units : sequence of (reflector_opt.design._design.Design, reflector_opt.model._noise.Mismatch)
        The printed units (:func:`reflector_opt.asbuilt._batchforecast.predicted_units`).
    step_deg : float
        Pose-grid step, degrees.

    Returns
    -------
    dict
        JSON-ready: ``angle_deg`` and ``drift_deg`` (``mean``, ``max`` over the units,
        degrees), ``window_mm`` and ``peak_mm`` (per sensor, the smallest over the units, mm)
        and ``clearance_mm`` (the smallest, mm).
    """
    found = [unit_figures(built, mismatch, step_deg) for built, mismatch in units]
    angle = np.array([f.angle_deg for f in found])
    drift = np.array([f.drift_deg for f in found])
    return {
        "angle_deg": {"mean": float(angle.mean()), "max": float(angle.max())},
        "drift_deg": {"mean": float(drift.mean()), "max": float(drift.max())},
        "window_mm": np.min([f.window_mm for f in found], axis=0).tolist(),
        "peak_mm": np.min([f.peak_mm for f in found], axis=0).tolist(),
        "clearance_mm": float(min(f.clearance_mm for f in found)),
    }
