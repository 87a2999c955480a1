"""The identification's model-form bias, simulated for a print correction.

The identification explains each unit's calibration data with the fast model. A real sensor
has physics the fast model lacks (a rough mirror lobe, light spreading under the resin's
surface, the LED's true pattern, light leaking inside the package, ambient light); to
explain their effect the fit moves the geometry — in the default design mostly the sphere
centre's height and the seats' tilts towards their detectors, by tens of µm and tenths of a
degree. Every unit of a batch carries the same physics, so this bias looks exactly like a
systematic print deviation, and a correction would print it into the next batch.

:func:`model_form_bias` measures it by simulation when the identification files do not
carry it (:mod:`reflector_opt.asbuilt._batch` reads it when they do): for each effect of
:class:`~reflector_opt.tolerance._model_form.ModelForm` alone, at its moderate default, a unit
built exactly to the drawing (no print deviation, no read-out error, the design's surface)
with that physics is recorded noise-free on a Sobol plan and identified without a
model-form term of its own; what the identification finds is that effect's bias b_k. The
effects' true sizes and signs are not known, so each is taken as an independent uncertainty
of ±b_k (one standard deviation): the batch mean's covariance gains ``Σ_k b_k b_kᵀ``, common
to all units (it does not average out), before the significance test
(:func:`reflector_opt.asbuilt._pooling.pool`).
"""

from dataclasses import replace

import numpy as np

from reflector_opt.asbuilt._batch import Batch
from reflector_opt.asbuilt._identification import identify
from reflector_opt.asbuilt._model_form_terms import reference_units
from reflector_opt.asbuilt._parameters import REFERENCE_PRIOR_STD
from reflector_opt.asbuilt._problem import UnitData
from reflector_opt.calibration._plans import make_plan
from reflector_opt.util._errors import InputError

#: How a correction weighs the model-form bias (:func:`weigh_model_form`).
MODES = ("auto", "simulate", "none")

#: Poses of the simulated calibration (a Sobol plan, as the benchmark's).
N_POSES = 200


def model_form_bias(
    design,
    *,
    model_form=None,
    tolerances=None,
    surface_std=None,
    reference_std=REFERENCE_PRIOR_STD,
    n_poses=N_POSES,
    seed=0,
):
    """The geometry an identification reports for units built exactly, one per effect.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        The drawing the batch was printed from.
    model_form : reflector_opt.tolerance._model_form.ModelForm, optional
        The effects and their sizes (default ``ModelForm()``, the moderate defaults); the
        exact reference's physics and each optical effect that is switched on give one entry
        (:func:`reflector_opt.asbuilt._model_form_terms.reference_units`; crosstalk and ambient
        light are constant couplings the offsets take up exactly).
    tolerances : reflector_opt.tolerance._tolerances.Tolerances, optional
        The identification's prior (the batch's; default the tolerance model's).
    surface_std : dict, optional
        The prior of the surface (the batch's; default the identification's).
    reference_std : dict or None, optional
        The prior of the angle reference (the batch's; default the identification's; None:
        the reference taken as exact).
    n_poses : int
        Poses of the Sobol calibration plan.
    seed : int
        Seed of the plan.

    Returns
    -------
    reflector_opt.asbuilt._batch.Batch
        One "unit" per effect, labelled by the option's name: its identified geometry
        deviation is that effect's bias, with the identification's covariance.
    """
    plan = make_plan(design.workspace, "sobol", n_poses, seed)
    template = UnitData("plan", np.zeros((len(plan), len(design.sensors))), plan)
    batches = []
    for name, data in reference_units(design, template, model_form):
        result = identify(
            design,
            {name: (data.volts, data.angles_deg)},
            tolerances=tolerances,
            surface_std=surface_std,
            reference_std=reference_std,
            profiles=False,
            model_form=None,
        )
        batches.append(Batch.from_identification(result, source=f"model form: {name}"))
    return _joined(batches)


def _joined(batches):
    """One Batch holding the units of several one-unit batches of the same design."""
    first = batches[0]
    return Batch(
        design=first.design,
        names=first.names,
        prior_std=first.prior_std,
        labels=tuple(b.labels[0] for b in batches),
        deviations=np.concatenate([b.deviations for b in batches]),
        covariances=np.concatenate([b.covariances for b in batches]),
        blocks=np.concatenate([b.blocks for b in batches]),
        surfaces=np.concatenate([b.surfaces for b in batches]),
        sources=tuple(s for b in batches for s in b.sources),
        batch=None,
        prior=first.prior,
    )


def weigh_model_form(batch, mode="auto", seed=0):
    """The batch and the simulated biases to pool it with, as ``mode`` says.

    Parameters
    ----------
    batch : reflector_opt.asbuilt._batch.Batch
    mode : {"auto", "simulate", "none"}
        ``auto``: the model-form term the files record, or if they record none, simulated;
        ``simulate``: simulated, the files' term left out; ``none``: neither (the
        identification's model trusted).
    seed : int
        Seed of the simulated plan.

    Returns
    -------
    (reflector_opt.asbuilt._batch.Batch, reflector_opt.asbuilt._batch.Batch or None)
        The batch (its recorded term dropped unless used) and the simulated biases or None:
        the arguments of :func:`reflector_opt.asbuilt._pooling.pool`.
    """
    if mode not in MODES:
        raise InputError(f"model form: expected one of {', '.join(MODES)}, got {mode!r}")
    recorded = batch.systematic is not None and bool(np.any(batch.systematic))
    if recorded and mode != "auto":
        batch = replace(batch, systematic=None)
    if mode == "none" or (mode == "auto" and recorded):
        return batch, None
    return batch, model_form_bias(batch.design, **batch.prior_options(), seed=seed)
