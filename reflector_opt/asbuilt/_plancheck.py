"""A plan for identification checked by identifying simulated units recorded on it.

:func:`check_plans` records simulated units
(:func:`reflector_opt.asbuilt._modelunit.simulated_units`: built units with exact optics the
fast model lacks, or units of the model) on each plan, identifies each alone and reports, per
plan, the achieved parameter errors and the angle errors of the identified model against the
units' Cramér–Rao floor (:class:`CheckRow`).
"""

import time
from dataclasses import dataclass

import numpy as np

from reflector_opt.asbuilt._estimator import AsBuiltModel
from reflector_opt.asbuilt._identification import identify
from reflector_opt.asbuilt._modelunit import simulated_units, true_parameters
from reflector_opt.asbuilt._parameters import ParameterLayout
from reflector_opt.tolerance._builtunit import (
    REFERENCE_SIGMA_DEG,
    built_unit_protocol,
    crlb_floor_deg,
)
from reflector_opt.tolerance._planning import N_VALIDATION


@dataclass(frozen=True)
class CheckRow:
    """One plan checked by identifying simulated built units on it.

    Attributes
    ----------
    pattern : str
    n_poses : int
    achieved : numpy.ndarray
        Shape (p,): RMS over the units of (estimate − truth) / prior std per parameter.
    rms_deg : numpy.ndarray
        Pitch and roll: RMS angle error of the identified model inverted at the validation
        poses, pooled over the units (RMS of the units' RMS), degrees.
    floor_deg : numpy.ndarray
        The units' Cramér–Rao floor at the same poses, pooled alike, degrees.
    inflation : float
        The largest Birge ratio s² of the units' fits.
    seconds : float
        Wall time of the identifications, s.
    """

    pattern: str
    n_poses: int
    achieved: np.ndarray
    rms_deg: np.ndarray
    floor_deg: np.ndarray
    inflation: float
    seconds: float

    def to_dict(self, names):
        """JSON-ready, with the angle errors' ratio to the floor."""
        ratio = self.rms_deg / self.floor_deg
        return {
            "pattern": self.pattern,
            "n_poses": self.n_poses,
            "achieved_error_prior_ratio": dict(zip(names, self.achieved.tolist(), strict=True)),
            "rms_deg": {"pitch": float(self.rms_deg[0]), "roll": float(self.rms_deg[1])},
            "floor_ratio": {"pitch": float(ratio[0]), "roll": float(ratio[1])},
            "inflation": self.inflation,
            "seconds": self.seconds,
        }


def _angle_rms_deg(result, validation):
    """RMS pitch and roll error of an identified unit's model inverted at validation data."""
    estimate = AsBuiltModel(*result.as_built(0)).fit().predict(validation.volts)
    return np.sqrt(np.mean((estimate - validation.angles_deg) ** 2, axis=0))


def check_plans(
    design,
    plans,
    *,
    n_units=3,
    seed=0,
    truth="built",
    n_validation=N_VALIDATION,
    progress=None,
    **prior,
):
    """Identify simulated units on each plan and measure what the fit achieves.

    Each unit records the plan with its noise and the angle reference's
    (:func:`~reflector_opt.tolerance._builtunit.built_unit_protocol`: for built units the same
    draws as :func:`reflector_opt.tolerance._planning.predict_plans` for the same plan and
    seed), is identified alone (:func:`~reflector_opt.asbuilt._identification.identify`, no
    profiles), and its identified model is inverted at the validation poses.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        Two sensors.
    plans : sequence of (str, array_like)
        (pattern name, poses (n, 2) in degrees).
    n_units : int
        Units per plan (the same units for every plan).
    seed : int
        Seed of the units and every noise draw.
    truth : {"built", "model"}
        :func:`~reflector_opt.asbuilt._modelunit.simulated_units`: built units (exact optics,
        the model-form error included) or the model's (the prediction's own assumptions).
    n_validation : int
        Validation poses per unit.
    progress : callable, optional
        Called with a short text before each plan.
    **prior
        ``tolerances``, ``surface_std``, ``reference_sigma_deg``: as in
        :func:`~reflector_opt.asbuilt._poses.pose_information`.

    Returns
    -------
    list of CheckRow
    """
    layout = ParameterLayout(design, 1, prior.get("tolerances"), prior.get("surface_std"))
    units = simulated_units(layout, truth, n_units, seed)
    # exact reference and optics, as the plans' information: no reference, spread or terms
    settings = {"design": design, "reference_sigma_deg": REFERENCE_SIGMA_DEG, **prior}
    settings.update(reference_std=None, model_form=None, subsurface_std=None)
    out = []
    for pattern, poses in plans:
        if progress is not None:
            progress(f"identifying {n_units} units on {pattern} {len(poses)} poses")
        started = time.perf_counter()
        found = [_identify_unit(unit, poses, seed, n_validation, settings) for unit in units]
        errors, rms, floors, inflation = zip(*found, strict=True)
        pooled = [np.sqrt(np.mean(np.square(v), axis=0)) for v in (errors, rms, floors)]
        seconds = time.perf_counter() - started
        out.append(CheckRow(pattern, len(poses), *pooled, float(max(inflation)), seconds))
    return out


def _identify_unit(unit, poses, seed, n_validation, settings):
    """Record a unit on a plan, identify it; its scaled errors, angle RMS, floor, s²."""
    design = settings["design"]
    protocol = built_unit_protocol(
        unit,
        poses,
        n_validation=n_validation,
        seed=seed,
        reference_sigma_deg=settings["reference_sigma_deg"],
    )
    calibration, validation = protocol.calibration, protocol.validation
    result = identify(
        design,
        {"1": (calibration.volts, calibration.angles_deg)},
        profiles=False,
        **{k: v for k, v in settings.items() if k != "design"},
    )
    prior = result.layout.prior_std()
    free = prior > 0
    error = ((result.x - true_parameters(design, unit)) / np.where(free, prior, 1.0))[free]
    return (
        error,
        _angle_rms_deg(result, validation),
        crlb_floor_deg(unit, validation.angles_deg),
        result.inflation,
    )
