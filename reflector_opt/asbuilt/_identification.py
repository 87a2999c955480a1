"""As-built identification: what a batch's calibration data say about how each unit was printed.

:func:`identify` fits, to the calibration samples of one or more units (and, if measured,
each sensor's flat-target curve), the as-built parameters of
:class:`~reflector_opt.asbuilt._parameters.ParameterLayout` — per unit the reflector's radius and
centre, each sensor's seat (standoff, shifts, tilts), gain, offset and emitter (beam divergence and
source size), the zero offsets and twist of the angle reference its calibration was read by,
and the amplitudes of the model-form signatures of each sensor
(:mod:`~reflector_opt.asbuilt._model_form_terms`, whose bias is subtracted); shared by the batch the
surface (ρ, f) and the resin's sub-surface spread ℓ — as a maximum a posteriori estimate
with the tolerance model as the prior
(:class:`~reflector_opt.asbuilt._problem.IdentificationProblem`), by
:func:`scipy.optimize.least_squares`
(Levenberg–Marquardt, MINPACK: the prior keeps every step near the design, and the
surface's (ρ, f) are clipped to [0, 1] inside the model, so the fit needs no bounds — with
bounds the trust-region methods took three to five times as many iterations; forward
differences in the iterations, central ones for the covariance). What the data cannot
separate stays near its prior instead of wandering; each parameter carries its posterior
std, its prior std and whether the data determine it, and each unit the combinations the
data determine (:mod:`~reflector_opt.asbuilt._uncertainty`).
"""

import time

import numpy as np
from scipy.optimize import least_squares

from reflector_opt.asbuilt._model_form_terms import model_form_names, model_form_terms
from reflector_opt.asbuilt._parameters import (
    REFERENCE_PRIOR_STD,
    SUBSURFACE_PRIOR_STD_MM,
    ParameterLayout,
)
from reflector_opt.asbuilt._problem import IdentificationProblem, UnitData
from reflector_opt.asbuilt._result import Identification
from reflector_opt.asbuilt._uncertainty import (
    birge_ratio,
    block_labels,
    combinations,
    cross_validation_ratio,
    posterior_covariance,
    profile_interval,
)
from reflector_opt.tolerance._builtunit import REFERENCE_SIGMA_DEG
from reflector_opt.tolerance._model_form import ModelForm
from reflector_opt.util._errors import FitError, InputError
from reflector_opt.util._progress import no_progress

#: Parameters given a profile-likelihood interval: the shared surface and each unit's radius.
PROFILED = ("reflectance", "specular_fraction", "reflector_radius_mm")

#: The physics the model lacks whose effect enters the covariance by default.
DEFAULT_MODEL_FORM = ModelForm()

#: A fit whose data χ² per degree of freedom exceeds this is refused: the data cannot come
#: from a unit of this design (its residuals are tens of times the noise).
MAX_BIRGE_RATIO = 400.0


def _as_units(samples, curves):
    """UnitData in the data's order from {label: UnitSamples or (volts, angles)}."""
    units = []
    for label, sample in samples.items():
        volts, angles = (sample.volts, sample.angles_deg) if hasattr(sample, "volts") else sample
        volts, angles = np.asarray(volts, dtype=float), np.asarray(angles, dtype=float)
        if volts.ndim != 2 or angles.shape != (len(volts), 2):
            raise InputError(f"unit {label}: expected (n, sensors) voltages and (n, 2) angles")
        if not (np.isfinite(volts).all() and np.isfinite(angles).all()):
            raise InputError(f"unit {label}: voltages and angles must be finite")
        units.append(UnitData(str(label), volts, angles, tuple(curves.get(str(label), ()))))
    unknown = set(curves) - {u.label for u in units}
    if unknown:
        raise InputError(
            f"flat-target curves: unit {sorted(unknown)[0]} is not in the calibration data "
            f"(units: {', '.join(u.label for u in units)})"
        )
    return units


def _check_workspace(design, units, margin_deg=1.0):
    """Refuse samples more than ``margin_deg`` outside the design's workspace or with the
    wrong number of sensors."""
    workspace = design.workspace
    lo = np.array([workspace.pitch_deg[0], workspace.roll_deg[0]]) - margin_deg
    hi = np.array([workspace.pitch_deg[1], workspace.roll_deg[1]]) + margin_deg
    for data in units:
        if data.volts.shape[1] != len(design.sensors):
            raise InputError(
                f"unit {data.label}: {data.volts.shape[1]} voltages per sample, but the design "
                f"has {len(design.sensors)} sensors"
            )
        outside = np.any((data.angles_deg < lo) | (data.angles_deg > hi), axis=1)
        if outside.any():
            pitch, roll = data.angles_deg[np.argmax(outside)]
            raise InputError(
                f"unit {data.label}: pose ({pitch:g}°, {roll:g}°) lies outside the design's "
                f"workspace (pitch {workspace.pitch_deg}, roll {workspace.roll_deg})"
            )


def _fit(problem, start):
    """The MAP estimate by Levenberg–Marquardt; FitError if it fails."""
    free = problem.free

    def full(z):  # the whole parameter vector of the free parameters z
        x = start.copy()
        x[free] = z
        return x

    try:
        result = least_squares(
            lambda z: problem.residuals(full(z)),
            start[free],
            jac=lambda z: problem.jacobian(full(z), central=False)[:, free],
            x_scale=problem.prior_std[free],
            method="lm",
            ftol=1e-6,
            xtol=1e-6,
            max_nfev=100,
        )
    except InputError as exc:  # a trial unit no design can be: a collision, a negative beam
        raise FitError(
            f"identification: the data do not fit this design (on the way the fit met a unit "
            f"that cannot be built: {exc}); check the design file, the units' wiring (v1, v2) "
            "and the sign of the angles"
        ) from None
    if result.status <= 0:
        raise FitError(f"identification did not converge: {result.message}")
    return full(result.x), result.nfev


def identify(
    design,
    samples,
    *,
    curves=None,
    tolerances=None,
    surface_std=None,
    reference_sigma_deg=REFERENCE_SIGMA_DEG,
    reference_std=REFERENCE_PRIOR_STD,
    profiles=True,
    model_form=DEFAULT_MODEL_FORM,
    subsurface_std=SUBSURFACE_PRIOR_STD_MM,
    progress=None,
):
    """Identify the as-built parameters of a batch of units from their calibration data.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        The design the units were printed from.
    samples : dict
        Unit label → :class:`reflector_opt.calibration._files.UnitSamples` (as
        :func:`~reflector_opt.calibration._files.read_calibration_csv` returns) or a pair
        ``(volts, angles_deg)`` of shapes (n, n_sensors) V and (n, 2) degrees.
    curves : dict, optional
        Unit label → sequence of :class:`~reflector_opt.asbuilt._problem.Curve`: flat-target
        curves of that unit's sensors, measured before assembly against a flat sample of
        the reflector's material.
    tolerances : reflector_opt.tolerance._tolerances.Tolerances, optional
        The prior of the geometry and read-out (default: the tolerance model's defaults).
    surface_std : dict, optional
        Prior std of ``reflectance`` and ``specular_fraction`` (default
        :data:`~reflector_opt.asbuilt._parameters.SURFACE_PRIOR_STD`).
    reference_sigma_deg : float, optional
        RMS noise of the angle reference at each calibration pose, degrees.
    reference_std : dict or None, optional
        Prior std of each unit's reference zero offsets and twist, degrees, by
        :data:`~reflector_opt.asbuilt._parameters.REFERENCE_NAMES` (default
        :data:`~reflector_opt.asbuilt._parameters.REFERENCE_PRIOR_STD`;
        :func:`~reflector_opt.asbuilt._parameters.reference_std_of` gives them from operating
        conditions). None: the reference is taken as exact (anchored by a known mechanical
        zero), no reference parameters.
    profiles : bool, optional
        Compute the profile-likelihood intervals of :data:`PROFILED`.
    model_form : reflector_opt.tolerance._model_form.ModelForm or None, optional
        The physics the model lacks whose signatures, per sensor, enter the fit with
        unit-normal amplitudes, and the fast model's bias from the exact reference
        (:mod:`~reflector_opt.asbuilt._model_form_terms`; default the documented sizes,
        ``ModelForm()``); None: the fast model alone, no bias, no amplitudes.
    subsurface_std : float or None, optional
        Prior std of the batch's sub-surface spread ℓ, mm, about
        :data:`~reflector_opt.asbuilt._parameters.SUBSURFACE_NOMINAL_MM` (default
        :data:`~reflector_opt.asbuilt._parameters.SUBSURFACE_PRIOR_STD_MM`); None: no spread
        (an opaque surface).
    progress : callable, optional
        ``progress(fraction, message)`` before the fit and before the covariances and
        intervals (:class:`reflector_opt.util._progress.Progress`).

    Returns
    -------
    reflector_opt.asbuilt._result.Identification

    Raises
    ------
    InputError
        Fewer samples than parameters, poses outside the workspace, curves of unknown units
        or sensors, data no unit of this design could give, or a fit that does not converge
        (:class:`~reflector_opt.util._errors.FitError`).
    """
    started = time.perf_counter()
    layout = ParameterLayout(
        design,
        len(samples) or 1,
        tolerances,
        surface_std,
        reference_std,
        subsurface_std,
        model_form_names(model_form, len(design.sensors)),
    )
    units = _checked_units(design, samples, curves, reference_sigma_deg, layout)
    progress = progress or no_progress
    terms = None
    if model_form is not None:
        progress(0.0, "model-form terms: the nominal unit with each optical effect")
        terms = model_form_terms(design, units, model_form, subsurface_std is not None)
    problem = IdentificationProblem(layout, units, reference_sigma_deg, terms)
    problem.check_counts()
    progress(0.0, f"fitting {problem.layout.size} as-built parameters of {len(units)} unit(s)")
    x, evaluations = _fit(problem, np.zeros(problem.layout.size))
    progress(0.05, "covariances" + (" and profile intervals" if profiles else ""))
    result = _identification(problem, x, profiles, evaluations, started, progress)
    progress(1.0, "identified")
    return result


def _checked_units(design, samples, curves, reference_sigma_deg, layout):
    """The units' data checked against the design: InputError on what cannot be fitted.

    With reference parameters, readings may lie outside the workspace by 1° plus three prior
    std of the zero offset (a true pose at the edge read through the reference's offset).
    """
    if not samples:
        raise InputError("identification: the calibration data hold no unit")
    if not (np.isfinite(reference_sigma_deg) and 0 <= reference_sigma_deg <= 5):
        raise InputError(f"reference_sigma_deg: expected 0 to 5°, got {reference_sigma_deg}")
    units = _as_units(samples, dict(curves or {}))
    zero_std = [layout.reference_std[n] for n in layout.reference_names[:2]]
    _check_workspace(design, units, 1.0 + 3.0 * max(zero_std, default=0.0))
    for data in units:
        for curve in data.curves:
            if not 0 <= curve.sensor < len(design.sensors):
                raise InputError(f"unit {data.label}: no sensor {curve.sensor + 1} in the design")
    return units


def _covariance(problem, x):
    """The data Jacobian at ``x``, the inflation s² (block cross-validation over the poses),
    the posterior covariance and its model-form share.

    FitError when the residuals are too large for the data to come from this design. The
    model-form share is what the covariance loses when the amplitudes are known:
    ``Σ − Σ|amplitudes`` (zero without amplitudes).
    """
    data_jacobian = problem.data_jacobian(x)
    residuals = problem.data_residuals(x)
    gross = birge_ratio(residuals, data_jacobian, problem.prior_std)
    if gross > MAX_BIRGE_RATIO:
        raise FitError(
            f"identification: the data do not fit this design (residuals "
            f"{np.sqrt(gross):.0f}× the noise after the fit); check the design file, the "
            "units' wiring (v1, v2) and the sign of the angles"
        )
    inflation = cross_validation_ratio(
        residuals, data_jacobian, problem.prior_std, _blocks(problem.units)
    )
    cov = posterior_covariance(data_jacobian, problem.prior_std, inflation)
    known = problem.prior_std.copy()
    for u in range(len(problem.units)):
        known[problem.layout.model_form_slice(u)] = 0.0
    share = cov - posterior_covariance(data_jacobian, known, inflation)
    return data_jacobian, inflation, cov, share


def _blocks(units):
    """Block label of every data residual: each unit's calibration poses by tile of the
    workspace (:func:`~reflector_opt.asbuilt._uncertainty.block_labels`), each curve a block."""
    labels, start = [], 0
    for data in units:
        tiles = block_labels(data.angles_deg, data.volts.shape[1])
        labels.append(start + tiles)
        start += int(tiles.max()) + 1
        for curve in data.curves:
            labels.append(np.full(curve.volts.size, start))
            start += 1
    return np.concatenate(labels)


def _identification(problem, x, profiles, evaluations, started, progress):
    """The :class:`Identification` of the MAP estimate ``x``: covariances, combinations,
    profile intervals (each reported through ``progress``, from 0.4 to 1) and residuals."""
    layout, units = problem.layout, problem.units
    data_jacobian, inflation, cov, systematic = _covariance(problem, x)
    names = layout.names([u.label for u in units])
    intervals = {}
    if profiles:
        full = problem.jacobian(x, data_jacobian=data_jacobian)
        intervals = _profiles(problem, x, full, cov, inflation, names, progress)
    return Identification(
        layout=layout,
        labels=tuple(u.label for u in units),
        x=x,
        covariance=cov,
        systematic_covariance=systematic,
        inflation=inflation,
        residual_rms_v=np.array(
            [np.sqrt(np.mean(problem.misfit_v(x, u) ** 2, axis=0)) for u in range(len(units))]
        ),
        combinations=[_unit_combinations(layout, cov, names, u) for u in range(len(units))],
        profiles=intervals,
        evaluations=evaluations,
        seconds=time.perf_counter() - started,
        n_samples=tuple(len(d.volts) for d in units),
        n_curves=tuple(len(d.curves) for d in units),
        reference_sigma_deg=float(problem.reference_sigma_deg),
        terms=problem.terms,
    )


def _unit_combinations(layout, cov, names, u):
    """The combinations of unit ``u``'s (and the shared) parameters the data determine."""
    index = layout.unit_indices(u)
    return combinations(
        cov[np.ix_(index, index)],
        layout.prior_std()[index],
        [names[i] for i in index],
        layout.words,
    )


def _profiles(problem, x, jacobian, cov, inflation, names, progress):
    """Profile intervals of the shared surface and every unit's radius, by name;
    ``jacobian`` is the Jacobian of all residuals at ``x`` (the model-form amplitudes are
    among the parameters profiled over, so the intervals carry them)."""
    nominal = problem.layout.nominal()
    bounds = problem.layout.bounds()
    out = {}
    todo = [j for j, n in enumerate(names) if n.split(": ")[-1] in PROFILED and problem.free[j]]
    for done, j in enumerate(todo):
        name = names[j]
        progress(0.4 + 0.6 * done / len(todo), f"profile interval of {name}")
        out[name] = profile_interval(
            name,
            problem.residuals,
            x,
            jacobian,
            j,
            float(np.sqrt(cov[j, j])),
            bounds,
            inflation,
            problem.n_data,
            nominal[j],
        )
    return out
