"""A material's reflectance, specular fraction and sub-surface spread from flat-target curves.

A surface of reflectance ρ returns the share f of it like a mirror and 1 − f diffusely
(:mod:`reflector_opt.model._surface`); a translucent resin returns the diffuse share from
around where the light entered, spread over a length ℓ. A sensor facing a flat sample of it
squarely at distance d couples ``η(d) = ρ · [f · η_mirror(d) + (1 − f) · η_Lambert(d) ·
R(d; ℓ)]`` (:mod:`reflector_opt.model._flat_fit`). The parts have different shapes: the
mirror's peaks nearer and falls off as the image source recedes, roughly as 1/(2d)², the
Lambertian one as 1/d² with its own near-field shape, which the spread flattens. A curve
against a flat coupon of the material therefore fixes ρ, f and ℓ once the sensor is known;
:func:`fit_material` fits them, with the sensor either held (fitted before against a
reference target) or fitted jointly from a curve of the same sensor against a reference of
known ρ and f (a first-surface mirror, or a white diffuse card). docs/guide.md, "Measuring
the reflector's material", is the lab recipe; docs/model.md, "Measuring the material", the
model and what the intervals mean.
"""

from dataclasses import dataclass, fields

import numpy as np

from reflector_opt.model._flat_fit import (
    FlatCurve,
    FlatSolution,
    fit_flat_curves,
    refit_with_pattern,
)
from reflector_opt.model._flat_target import signal_readings
from reflector_opt.model._optics import flat_target_coupling
from reflector_opt.util._display import Summarised, fmt
from reflector_opt.util._errors import InputError

#: RMS noise of a reading assumed when none is given, V (the design's default noise).
DEFAULT_SIGMA_V = 0.002
#: A curve whose RMS residual exceeds this many σ_V is not described by the model.
MAX_MISFIT = 3.0
#: The LED patterns other than the model's Gaussian whose effect is the model-form term.
PATTERNS = ("cosine_power", "two_gaussian")
#: The drop in χ² that fitting the spread ℓ must give to be kept: the 99 % point of χ² with
#: one degree of freedom. Below it the data do not resolve ℓ and it is left at 0.
SPREAD_CHI2 = 6.63
#: Standard normal quantile of the two-sided 90 % intervals.
_Z90 = 1.6449
#: Below this sine of the angle between the mirror and Lambertian curves (as vectors over the
#: measured distances) the two are collinear to rounding and f cannot be separated from ρ.
_MIN_SINE = 1e-3
_SQ = "subsurface_sq_mm2"
_NAMES = ("reflectance", "specular_fraction", _SQ)
#: The physical range of each: ρ in (0, 1], f in [0, 1], ℓ² in [0, 1] mm².
_RANGE = {"reflectance": (1e-3, 1.0), "specular_fraction": (0.0, 1.0), _SQ: (0.0, 1.0)}


@dataclass(frozen=True, repr=False)
class MaterialFit(Summarised):
    """Result of :func:`fit_material`.

    Attributes
    ----------
    reflectance, specular_fraction : float
        Fitted ρ and f of the sample, each in [0, 1].
    reflectance_sigma, specular_fraction_sigma : float
        Their 1σ statistical standard errors (the readings' scatter, at least σ_V).
    correlation : float
        Correlation of the statistical errors of ρ and f (−1 to 1).
    reflectance_model_form_sigma, specular_fraction_model_form_sigma : float
        Their model-form std: the shifts other LED patterns (:data:`PATTERNS`) give the
        estimate, added in quadrature (0 when not computed).
    reflectance_interval, specular_fraction_interval : tuple of float
        90 % intervals from both stds, within [0, 1].
    subsurface_mm : float or None
        Fitted sub-surface spread length ℓ, mm; None when not fitted, not resolved (fitting
        it lowers χ² by less than :data:`SPREAD_CHI2`) or not determined (no diffuse share).
    subsurface_interval_mm : tuple of float or None
        Its 90 % interval, mm; when ℓ is not resolved, the interval of the fit with it (its
        upper end a limit).
    offset_v : float
        The sample curve's fitted output offset, V.
    rms_residual_v, max_residual_v : float
        RMS and largest absolute residual of the sample curve's readings, V.
    points, clamped : int
        Readings of the sample curve used, and left out at a clamp.
    sigma_v : float
        The readings' noise the fit was judged against, V.
    misfit : bool
        True when a curve's RMS residual exceeds :data:`MAX_MISFIT` σ_V (a fit accepted
        with ``accept_misfit``: its values are effective).
    reference_rms_v : float or None
        RMS residual of the reference curve fitted jointly, V (None: the sensor was held).
    sensor : reflector_opt.model._sensors.SensorModel
        The sensor of the fit: held, or fitted jointly with the reference.
    """

    reflectance: float
    specular_fraction: float
    reflectance_sigma: float
    specular_fraction_sigma: float
    correlation: float
    reflectance_model_form_sigma: float
    specular_fraction_model_form_sigma: float
    reflectance_interval: tuple
    specular_fraction_interval: tuple
    subsurface_mm: float | None
    subsurface_interval_mm: tuple | None
    offset_v: float
    rms_residual_v: float
    max_residual_v: float
    points: int
    clamped: int
    sigma_v: float
    misfit: bool
    reference_rms_v: float | None
    sensor: object

    def _summary(self):
        """Title and (label, value) rows of :class:`MaterialFit`."""
        rows = [
            ("reflectance ρ", f"{fmt(self.reflectance)} ± {fmt(self.reflectance_sigma, 2)}"),
            (
                "specular fraction f",
                f"{fmt(self.specular_fraction)} ± {fmt(self.specular_fraction_sigma, 2)}",
            ),
            (
                "90 % interval of ρ",
                f"{fmt(self.reflectance_interval[0])}–{fmt(self.reflectance_interval[1])}",
            ),
            (
                "90 % interval of f",
                f"{fmt(self.specular_fraction_interval[0])}–{fmt(self.specular_fraction_interval[1])}",
            ),
            (
                "sub-surface spread ℓ",
                "not determined"
                if self.subsurface_mm is None
                else fmt(self.subsurface_mm, unit="mm"),
            ),
            ("correlation of ρ and f", fmt(self.correlation)),
            ("RMS residual", fmt(self.rms_residual_v, unit="V")),
            ("max residual", fmt(self.max_residual_v, unit="V")),
            ("readings used", f"{self.points} ({self.clamped} clamped left out)"),
        ]
        return "MaterialFit", rows

    def to_dict(self):
        """JSON-ready dict of the attributes (the sensor as its ``to_dict``)."""
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        out["sensor"] = self.sensor.to_dict()
        for key in ("reflectance_interval", "specular_fraction_interval", "subsurface_interval_mm"):
            out[key] = None if out[key] is None else list(out[key])
        return out


def fit_material(
    distance_mm,
    volts,
    model,
    *,
    reference=None,
    sigma_v=DEFAULT_SIGMA_V,
    subsurface=True,
    model_form=True,
    clamp_margin_v=0.01,
    max_sigma_f=0.1,
    accept_misfit=False,
):
    """Fit a flat sample's reflectance ρ, specular fraction f and sub-surface spread ℓ.

    The readings are ``V = model.output_voltage(η) + c`` with η of the module notes and c
    the curve's output offset (:mod:`reflector_opt.model._flat_fit`: the read-out's gain is
    the sensor's, on the collector current; c takes up the read-out's offset, crosstalk and
    ambient light). ρ, f, c and ℓ² (the curve depends on ℓ² at first order) are fitted by
    bounded least squares, ρ in (0, 1], f in [0, 1], ℓ in [0, 1] mm; ℓ is kept where the data
    resolve it — where fitting it lowers χ² by more than :data:`SPREAD_CHI2` — and is else 0.
    With ``reference`` (a curve of the same sensor against a target
    of known ρ and f) the sensor's ω0, θ and gain and the reference's own offset are fitted
    with them, jointly; without it the sensor is held as given.

    **Uncertainty.** The statistical covariance is ``s² (JᵀJ)⁻¹`` over every fitted
    parameter, s² the residual variance over n − k but at least σ_V²: with a reference it
    holds the sensor's own uncertainty, held it takes the sensor as exact. The model-form
    term is what the fast model's Gaussian LED beam leaves out: the curves modelled at the
    nominal beam (``model``'s) and the fitted surface are remade with each pattern of
    :data:`PATTERNS` (closed form, :mod:`reflector_opt.model._flat_hankel`) and fitted again;
    each shift, of unknown sign, adds to the variance. The 90 % intervals take both,
    ± 1.645 std, cut at the bounds. An error in the reference's ρ scales the sample's ρ by the
    same factor and is in neither.

    **Refusals.** A curve whose RMS residual exceeds :data:`MAX_MISFIT` σ_V is not described
    by the model (a tilted coupon, a wrong zero, physics the model lacks): refused unless
    ``accept_misfit``. f is refused as not determined when its statistical std exceeds
    ``max_sigma_f`` or the mirror and Lambertian curves are collinear over the distances.

    Parameters
    ----------
    distance_mm, volts : array_like
        The sample curve: distances (mm, > 0) and output voltages (V).
    model : reflector_opt.model._sensors.SensorModel
        The sensor: held, or the start and nominal beam of the joint fit. A
        ``measured_curve`` it carries is not used.
    reference : reflector_opt.model._flat_target.MeasuredCurve, optional
        The same sensor's curve against a reference target, with that target's
        ``reflectance`` and ``specular_fraction``; taken as opaque (no spread).
    sigma_v : float, optional
        RMS noise of a reading, V.
    subsurface : bool, optional
        Fit ℓ (else ℓ = 0, an opaque sample).
    model_form : bool, optional
        Compute the model-form term (two more fits).
    clamp_margin_v : float, optional
        Readings within this many volts of saturation or the supply are left out, V.
    max_sigma_f : float, optional
        Largest acceptable statistical std of f.
    accept_misfit : bool, optional
        Return a fit whose residuals exceed :data:`MAX_MISFIT` σ_V (``misfit`` True).

    Returns
    -------
    MaterialFit

    Raises
    ------
    InputError
        Distances and voltages of different lengths, non-finite, or a distance not
        positive; too few or flat readings
        (:func:`~reflector_opt.model._flat_target.signal_readings`); a misfit; f not
        determined.
    """
    if not (np.isfinite(sigma_v) and sigma_v > 0):
        raise InputError(
            f"material curve: sigma_v must be a positive number of volts, got {sigma_v}"
        )
    d, v, used = _readings(distance_mm, volts, model, clamp_margin_v, "material curve")
    span = f"{d.min():.2f}–{d.max():.2f} mm"
    _check_shapes(d, model, span)
    curves = [FlatCurve(d, v)]
    if reference is not None:
        rd, rv, _ = _readings(
            reference.distance_mm, reference.volts, model, clamp_margin_v, "reference curve"
        )
        curves.insert(0, FlatCurve(rd, rv, reference.reflectance, reference.specular_fraction))
    options = {"fit_sensor": reference is not None, "subsurface": False, "sigma_v": sigma_v}
    solution = fit_flat_curves(curves, model, **options)
    spread = _spread_fit(curves, model, options, solution) if subsurface else None
    if spread is not None and _resolves(solution, spread, sigma_v):
        solution, options["subsurface"] = spread, True
    misfit = _check_misfit(solution, sigma_v, accept_misfit, reference is not None)
    _check_fraction(solution, max_sigma_f, span)
    shifts = _model_form(curves, solution, model, options) if model_form else []
    return _result(solution, shifts, used, sigma_v, misfit, spread)


def _spread_fit(curves, model, options, plain):
    """The fit with the sample's spread ℓ as well, started from ``plain``; None where the
    data leave it undetermined (no diffuse share)."""
    start = FlatSolution((*plain.names, _SQ), np.r_[plain.values, 0.05**2], None, model, ())
    spread = fit_flat_curves(curves, model, **{**options, "subsurface": True}, start=start)
    return spread if np.all(np.isfinite(spread.covariance)) else None


def _resolves(plain, spread, sigma_v):
    """True when fitting ℓ lowers χ² by more than :data:`SPREAD_CHI2` (σ the larger of σ_V
    and the fit's residual scatter)."""
    rss = [sum(float(r @ r) for r in fit.residuals_v) for fit in (plain, spread)]
    n = sum(r.size for r in spread.residuals_v)
    variance = max(rss[1] / max(n - len(spread.names), 1), sigma_v**2)
    return (rss[0] - rss[1]) / variance > SPREAD_CHI2


def _readings(distance_mm, volts, model, clamp_margin_v, what):
    """The readings that carry the coupling, checked: distances, voltages (mm, V), the mask."""
    d = np.asarray(distance_mm, dtype=float)
    v = np.asarray(volts, dtype=float)
    if d.ndim != 1 or d.shape != v.shape:
        raise InputError(f"{what}: distance_mm and volts must be 1-D and of equal length")
    if not (np.all(np.isfinite(d)) and np.all(np.isfinite(v))):
        raise InputError(f"{what}: distances and volts must be finite numbers")
    if np.any(d <= 0):
        raise InputError(f"{what}: distance_mm must be positive")
    used = signal_readings(v, model, what, clamp_margin_v=clamp_margin_v)
    return d[used], v[used], used


def _check_shapes(d, model, span):
    """Refuse distances over which the mirror and Lambertian curves are collinear."""
    basis = np.column_stack(
        [flat_target_coupling(d, model, 1.0, 1.0), flat_target_coupling(d, model, 1.0, 0.0)]
    )
    unit = basis / np.linalg.norm(basis, axis=0)
    cosine = float(np.clip(unit[:, 0] @ unit[:, 1], -1.0, 1.0))
    if np.sqrt(1.0 - cosine * cosine) < _MIN_SINE:
        raise InputError(
            f"material curve: the specular fraction is not determined: over {span} the mirror "
            "and Lambertian curves have the same shape; the distances must span the near "
            "range, through the curve's peak, and the far range"
        )


def _check_misfit(solution, sigma_v, accept, joint):
    """True if a curve's RMS residual exceeds MAX_MISFIT σ_V; InputError unless accepted."""
    names = ["reference curve", "material curve"] if joint else ["material curve"]
    for name, r in zip(names, solution.residuals_v, strict=True):
        rms = float(np.sqrt(np.mean(r * r)))
        if rms > MAX_MISFIT * sigma_v:
            if accept:
                return True
            raise InputError(
                f"{name}: the model does not describe the readings (RMS residual "
                f"{1e3 * rms:.2f} mV, {rms / sigma_v:.1f}× the noise σ_V {1e3 * sigma_v:.2f} mV, "
                f"more than {MAX_MISFIT:g}×): a tilted coupon, a wrong zero, or a reference or "
                "LED the model does not describe; accept_misfit (--accept-misfit) fits anyway"
            )
    return False


def _check_fraction(solution, max_sigma_f, span):
    """Refuse f as not determined when its statistical std exceeds ``max_sigma_f``."""
    f, sigma_f = solution.value("specular_fraction"), solution.sigma("specular_fraction")
    if not np.isfinite(sigma_f) or sigma_f > max_sigma_f:
        rms = np.sqrt(np.mean(solution.residuals_v[-1] ** 2))
        raise InputError(
            f"material curve: the specular fraction is not determined (f = {f:.2f} ± "
            f"{sigma_f:.2g}, more than ± {max_sigma_f:g}): over {span} the mirror and "
            "Lambertian curves have nearly the same shape; the distances must span the near "
            "range, through the curve's peak, and the far range (or the readings be less "
            f"noisy: residual RMS {1e3 * rms:.2g} mV)"
        )


def _model_form(curves, solution, model, options):
    """Shifts of (ρ, f, ℓ²) when the curves at the nominal beam and the fitted surface are
    made by each of :data:`PATTERNS` and fitted again."""
    at = solution
    if options["fit_sensor"]:  # the nominal beam: the model's, the rest as fitted
        values = solution.values.copy()
        values[0], values[1] = model.source_radius_mm, model.divergence_deg
        at = type(solution)(solution.names, values, solution.covariance, model, ())
    keys = [k for k in ("reflectance", "specular_fraction", _SQ) if k in solution.names]
    shifts = []
    for pattern in PATTERNS:
        refit = refit_with_pattern(curves, at, pattern, model, **options)
        shifts.append({k: refit.value(k) - at.value(k) for k in keys})
    return shifts


def _result(solution, shifts, used, sigma_v, misfit, spread):
    """The :class:`MaterialFit` of a solution, its model-form shifts and the fit with the
    spread (for ℓ's interval when the solution leaves it out)."""
    value = {k: solution.value(k) for k in _NAMES if k in solution.names}
    sigma = {k: solution.sigma(k) for k in value}
    form = {k: float(np.sqrt(sum(s[k] ** 2 for s in shifts))) for k in value}
    interval = {k: _interval(value[k], np.hypot(sigma[k], form[k]), *_RANGE[k]) for k in value}
    if _SQ not in value and spread is not None:
        interval[_SQ] = _interval(spread.value(_SQ), spread.sigma(_SQ), *_RANGE[_SQ])
    i, j = solution.names.index("reflectance"), solution.names.index("specular_fraction")
    product = sigma["reflectance"] * sigma["specular_fraction"]
    r = solution.residuals_v[-1]
    joint = len(solution.residuals_v) > 1
    return MaterialFit(
        reflectance=value["reflectance"],
        specular_fraction=value["specular_fraction"],
        reflectance_sigma=sigma["reflectance"],
        specular_fraction_sigma=sigma["specular_fraction"],
        correlation=float(solution.covariance[i, j] / product) if product > 0 else 0.0,
        reflectance_model_form_sigma=form["reflectance"],
        specular_fraction_model_form_sigma=form["specular_fraction"],
        reflectance_interval=interval["reflectance"],
        specular_fraction_interval=interval["specular_fraction"],
        subsurface_mm=float(np.sqrt(value[_SQ])) if _SQ in value else None,
        subsurface_interval_mm=tuple(np.sqrt(interval[_SQ]).tolist()) if _SQ in interval else None,
        offset_v=solution.value(f"offset_v_{len(solution.residuals_v) - 1}"),
        rms_residual_v=float(np.sqrt(np.mean(r * r))),
        max_residual_v=float(np.max(np.abs(r))),
        points=int(used.sum()),
        clamped=int(used.size - used.sum()),
        sigma_v=float(sigma_v),
        misfit=misfit,
        reference_rms_v=float(np.sqrt(np.mean(solution.residuals_v[0] ** 2))) if joint else None,
        sensor=solution.model,
    )


def _interval(value, std, low, high):
    """``value ± 1.645 std`` cut at the bounds [low, high]."""
    return (float(max(low, value - _Z90 * std)), float(min(high, value + _Z90 * std)))
