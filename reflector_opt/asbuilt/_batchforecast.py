"""The next batch, predicted with and without the print correction.

The identified units of a batch say how each was built: the systematic part that repeats
and each unit's own scatter. The next batch is predicted by printing **the same deviations**
again — each identified unit's whole block (geometry, gain, offset) and the batch's surface —
on the drawing: the original design (no correction) or the corrected one. The scatter of
the batch is kept; only the drawing changes (:func:`predicted_units`).

Each predicted unit is scored with the fast model over the workspace:

* its **resolution**: the Cramér–Rao 1σ pitch and roll resolution
  over poses (:func:`reflector_opt.analysis._resolution.resolution_over_poses`) from the
  unit's own voltage Jacobian
  (its gain included) and the design's σ_V with quantisation, on a pose grid; the
  worst case and the RMS over the grid (:func:`workspace_resolution`);
* its **calibration**: a simulated calibration on a Sobol plan of ``n_poses`` poses with the
  form chosen by cross-validation (:class:`~reflector_opt.calibration._selection.AutoModel`),
  validated on random poses with fresh noise: the RMS error per angle.

The batch's figure is the mean over its units (worst case: also the largest), and the gain
is the ratio without/with (> 1: the correction helps).
"""

import numpy as np

from reflector_opt.analysis._jacobian import values_and_jacobian
from reflector_opt.analysis._resolution import resolution_over_poses
from reflector_opt.asbuilt._parameters import ParameterLayout
from reflector_opt.calibration._plans import make_plan
from reflector_opt.calibration._selection import AutoModel
from reflector_opt.calibration._simulation import record, simulate_protocol, validation_error
from reflector_opt.model._forward import respond
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import json_number
from reflector_opt.util._seeds import stream_rng

#: Pose-grid step of the resolution over the workspace, degrees.
STEP_DEG = 0.5

#: Calibration poses of the predicted calibration (a Sobol plan).
N_POSES = 200

#: Validation poses per predicted unit.
N_VALIDATION = 2000


def workspace_resolution(volts, design, step_deg=STEP_DEG):
    """The Cramér–Rao resolution of a unit over its workspace: worst case and RMS.

    Parameters
    ----------
    volts : callable
        ``volts(pitch_deg, roll_deg)`` → output voltages, shape ``P + (n_sensors,)``, V
        (e.g. a :class:`~reflector_opt.tolerance._builtunit.BuiltUnit`'s ``volts``).
    design : reflector_opt.design._design.Design
        Its workspace and noise (σ_V with the ADC's quantisation).
    step_deg : float
        Pose-grid step, degrees.

    Returns
    -------
    dict
        ``worst_deg`` and ``rms_deg``, each ``{pitch, roll}``, degrees, and ``worst``, the
        larger worst case.
    """
    if not (np.isfinite(step_deg) and step_deg > 0):
        raise InputError(f"step_deg: expected a positive number, got {step_deg!r}")
    pitch, roll = np.broadcast_arrays(*design.workspace.grid(step_deg))
    _, jacobian = values_and_jacobian(volts, pitch, roll)
    found = resolution_over_poses(jacobian, design.noise.total_sigma_v)
    return {
        "worst_deg": dict(zip(("pitch", "roll"), found.worst_deg.tolist(), strict=True)),
        "rms_deg": dict(zip(("pitch", "roll"), found.rms_deg.tolist(), strict=True)),
        "worst": found.worst,
    }


def predicted_units(batch, design):
    """The batch's units printed again on ``design``: each unit's deviations kept.

    Parameters
    ----------
    batch : reflector_opt.asbuilt._batch.Batch
    design : reflector_opt.design._design.Design
        The drawing (the batch's own design, or a corrected one with the same sensors).

    Returns
    -------
    list of (reflector_opt.design._design.Design, reflector_opt.model._noise.Mismatch)
    """
    layout = ParameterLayout(design, 1)
    units = []
    for block, surface in zip(batch.blocks, batch.surfaces, strict=True):
        x = np.zeros(layout.size)
        x[: len(layout.shared_names)] = surface
        x[layout.unit_slice(0)] = block
        units.append(layout.unit_design(x, 0))
    return units


def _finite_tree(figures):
    """:func:`workspace_resolution`'s dict with non-finite values as None."""
    return {
        k: _finite_tree(v) if isinstance(v, dict) else json_number(v) for k, v in figures.items()
    }


def _calibration_rms(built, mismatch, plan, seed, index):
    """RMS calibration error per angle of predicted unit ``index``, degrees."""

    def recorder(angles_deg, rng, in_use):
        return record(built, angles_deg, rng, mismatch)

    rng = stream_rng(seed, "batch_calibration", index)
    protocol = simulate_protocol(recorder, built.workspace, plan, N_VALIDATION, rng, seed=seed)
    return validation_error(AutoModel(seed=seed), protocol)[1].rms_deg


def _batch_figures(units, step_deg, plan, seed):
    """Per unit and over the batch: resolution and (with a plan) calibration."""
    per_unit, calibration = [], []
    for k, (built, mismatch) in enumerate(units):

        def volts(pitch, roll, built=built, mismatch=mismatch):
            return mismatch.apply(respond(built, pitch, roll).volts)

        per_unit.append(workspace_resolution(volts, built, step_deg))
        if plan is not None:
            calibration.append(_calibration_rms(built, mismatch, plan, seed, k))
    worst = np.array([u["worst"] for u in per_unit])
    out = {
        "worst_resolution_deg": {
            "mean": json_number(worst.mean()),
            "max": json_number(worst.max()),
        },
        "units": [_finite_tree(u) for u in per_unit],
    }
    if calibration:
        rms = np.sqrt(np.mean(np.square(calibration), axis=0))
        out["calibration_rms_deg"] = {"pitch": float(rms[0]), "roll": float(rms[1])}
    return out


def predict_next_batch(
    batch, corrected, *, step_deg=STEP_DEG, calibration=True, n_poses=N_POSES, seed=0
):
    """The next batch's resolution and calibration, without and with the correction.

    Parameters
    ----------
    batch : reflector_opt.asbuilt._batch.Batch
        The identified batch (its ``design`` is the uncorrected drawing).
    corrected : reflector_opt.design._design.Design
        The corrected drawing.
    step_deg : float
        Pose-grid step of the resolution, degrees.
    calibration : bool
        Also simulate each unit's calibration (a Sobol plan of ``n_poses``).
    n_poses : int
        Calibration poses.
    seed : int
        Seed of the plan and the noise.

    Returns
    -------
    dict
        JSON-ready: ``without`` and ``with``, each ``worst_resolution_deg.{mean, max}``
        (degrees, over the units), ``units`` (per unit :func:`workspace_resolution`) and
        ``calibration_rms_deg.{pitch, roll}`` (RMS over the units); ``gain``, the ratio
        without/with of the mean worst-case resolution; ``method``. A figure that is not
        finite (no sensitivity somewhere in the workspace) is None.
    """
    plan = make_plan(batch.design.workspace, "sobol", n_poses, seed) if calibration else None
    out = {}
    for key, drawing in (("without", batch.design), ("with", corrected)):
        out[key] = _batch_figures(predicted_units(batch, drawing), step_deg, plan, seed)
    mean = [out[k]["worst_resolution_deg"]["mean"] for k in ("without", "with")]
    out["gain"] = json_number(mean[0] / mean[1]) if None not in mean and mean[1] > 0 else None
    out["method"] = {
        "model": "fast model, the identified units' deviations printed again",
        "step_deg": float(step_deg),
        "n_poses": int(n_poses) if calibration else None,
        "n_validation": N_VALIDATION if calibration else None,
        "seed": int(seed),
    }
    return out
