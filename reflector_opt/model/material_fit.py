"""A material's reflectance and specular fraction from a curve measured against a flat sample.

A surface of reflectance ρ returns the share f of it like a mirror and 1 − f diffusely
(:mod:`reflector_opt.model.surface`), so a sensor facing a flat sample squarely at distance d
couples ``η(d) = ρ · [f · η_mirror(d) + (1 − f) · η_Lambert(d)]``
(:func:`~reflector_opt.model.optics.flat_target_coupling`). The two curves have different
shapes: the mirror's peaks nearer and falls off as the image source recedes, roughly as
1/(2d)², the Lambertian one as 1/d² with its own near-field shape. A voltage-versus-distance
curve measured against a flat coupon of the material therefore fixes both ρ and f, once the
sensor itself is known — fitted first against a reference target of known ρ and f
(:func:`reflector_opt.model.measured.fit_sensor_model`). :func:`fit_material` does the fit;
docs/guide.md, "Measuring the reflector's material", is the lab recipe.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy.optimize import least_squares

from reflector_opt.model.flat_target import signal_readings
from reflector_opt.model.optics import flat_target_coupling
from reflector_opt.util.display import fmt, html_summary, text_summary
from reflector_opt.util.errors import InputError

__all__ = ["MaterialFit", "fit_material"]

#: Below this sine of the angle between the mirror and Lambertian curves (as vectors over the
#: measured distances) the two are collinear to rounding and f cannot be separated from ρ.
_MIN_SINE = 1e-3


@dataclass(frozen=True)
class MaterialFit:
    """Result of :func:`fit_material`.

    Attributes
    ----------
    reflectance : float
        Fitted reflectance ρ of the sample (0–1).
    specular_fraction : float
        Fitted mirror-like share f of the reflectance (0–1).
    reflectance_sigma, specular_fraction_sigma : float
        Their 1σ standard errors (dimensionless), from the curve's scatter.
    correlation : float
        Correlation coefficient of the errors of ρ and f (−1 to 1).
    rms_residual_v : float
        RMS of measured minus fitted voltage over the points used, V.
    max_residual_v : float
        Largest absolute residual over the points used, V.
    points : int
        Number of readings used.
    clamped : int
        Number of readings left out because the output was clamped at saturation or at the
        supply.
    """

    reflectance: float
    specular_fraction: float
    reflectance_sigma: float
    specular_fraction_sigma: float
    correlation: float
    rms_residual_v: float
    max_residual_v: float
    points: int
    clamped: int

    def __repr__(self):
        return text_summary(*_summary(self))

    def _repr_html_(self):
        return html_summary(*_summary(self))

    def to_dict(self):
        """JSON-ready dict of the attributes."""
        return asdict(self)


def fit_material(distance_mm, volts, model, *, clamp_margin_v=0.01, max_sigma_f=0.1):
    """Fit a flat sample's reflectance ρ and specular fraction f to its measured curve.

    Fits ``V(d) = model.output_voltage(flat_target_coupling(d, model, ρ, f))`` to the readings
    in least squares, with ρ in (0, 1] and f in [0, 1], the sensor's parameters (ω0, θ, e,
    S_area, the gain and the circuit) held as given.

    The method: away from its clamps the circuit is affine in the coupling
    (:mod:`reflector_opt.model.electronics`), and the coupling is linear in the two amplitudes
    a = ρ f and b = ρ (1 − f) of the mirror and Lambertian curves, each computed once. So the
    model is linear in (a, b): an ordinary linear least-squares fit, in the couplings the
    readings invert to (:meth:`~reflector_opt.model.sensors.SensorModel.coupling_from_voltage`),
    gives the unique optimum, with no start value to choose and no local minimum. That
    solution, moved into the bounds, starts ``scipy.optimize.least_squares`` on (ρ, f) with
    the bounds and the analytic Jacobian; inside the bounds it returns the linear solution
    unchanged, and where the data favour a value outside them (f a little above 1 for a
    mirror, from noise) it returns the best value on the bound. Voltage residuals are the
    coupling residuals times the constant slope of the circuit, so the fit in couplings is
    the fit in volts with the same weights.

    The standard errors come from the Jacobian J of the voltages with respect to (ρ, f) at
    the solution: covariance ``s² (JᵀJ)⁻¹`` with ``s²`` the residual variance over n − 2
    degrees of freedom — the readings' own scatter, model error included. They describe this
    curve only: the sensor's parameters count as exact. An error in the gain (or in the
    reflectance of the reference target it was fitted against) scales a and b alike, hence
    ρ by the same factor, and leaves f; errors in the shape parameters (ω0, θ) move f. At a
    bound the σ is the curvature's there: read it as a one-sided interval.

    Long because its docstring states the method and what the standard errors mean; the
    bounded fit and the covariance are functions of their own.

    Parameters
    ----------
    distance_mm : array_like
        Distances from the sensor to the flat sample, mm (> 0; repeated readings at one
        distance are allowed).
    volts : array_like
        Output voltage at each distance, V.
    model : reflector_opt.model.sensors.SensorModel
        The sensor, its parameters known (e.g. fitted against a reference target). A
        ``measured_curve`` it carries is not used: its correction belongs to the reference
        target's mix of mirror and diffuse light.
    clamp_margin_v : float, optional
        Readings within this many volts of ``model.saturation_v`` or ``model.supply_v`` count
        as clamped and are left out, V (the output leaves the linear range gradually).
    max_sigma_f : float, optional
        Largest acceptable standard error of f; above it f counts as not determined.

    Returns
    -------
    MaterialFit

    Raises
    ------
    InputError
        Distances and voltages of different lengths, non-finite or a distance not positive;
        every reading clamped, fewer than 4 readings unclamped or those flat
        (:func:`~reflector_opt.model.flat_target.signal_readings`); f not determined: the
        mirror and Lambertian curves are (nearly) proportional over the measured distances,
        or ``σ_f > max_sigma_f`` — the distances must span the near range, through the peak,
        and the far range.
    """
    d, v, used = _readings(distance_mm, volts, model, clamp_margin_v)
    n = int(used.sum())
    span = f"{d.min():.2f}–{d.max():.2f} mm"
    basis = _basis(d, model, span)
    measured = model.coupling_from_voltage(v)
    slope_v = 1.0 / (model.coupling_from_voltage(0.0) - model.coupling_from_voltage(1.0))

    x, jac = _bounded_fit(basis, measured, slope_v)
    rho, f = (float(value) for value in x)
    fitted = model.output_voltage(flat_target_coupling(d, model, rho, f))
    r = fitted - v
    variance = float(r @ r) / (n - 2)
    covariance = _covariance(jac, variance)
    sigma_rho, sigma_f = np.sqrt(np.abs(np.diag(covariance)))
    if not np.isfinite(sigma_f) or sigma_f > max_sigma_f:
        raise InputError(
            f"material curve: the specular fraction is not determined (f = {f:.2f} ± "
            f"{sigma_f:.2g}, more than ± {max_sigma_f:g}): over {span} the mirror and "
            "Lambertian curves have nearly the same shape; the distances must span the near "
            "range, through the curve's peak, and the far range (or the readings be less "
            f"noisy: residual RMS {1e3 * np.sqrt(variance):.2g} mV)"
        )
    product = sigma_rho * sigma_f
    correlation = float(covariance[0, 1] / product) if product > 0 else 0.0
    return MaterialFit(
        reflectance=rho,
        specular_fraction=f,
        reflectance_sigma=float(sigma_rho),
        specular_fraction_sigma=float(sigma_f),
        correlation=correlation,
        rms_residual_v=float(np.sqrt(np.mean(r * r))),
        max_residual_v=float(np.max(np.abs(r))),
        points=n,
        clamped=int(used.size - n),
    )


def _bounded_fit(basis, measured, slope_v):
    """(ρ, f) of the couplings ``measured`` on the mirror and Lambertian ``basis`` columns.

    The linear least-squares optimum in (a, b) = (ρ f, ρ (1 − f)), moved into the bounds,
    starts a bounded ``least_squares`` in (ρ, f) with the analytic Jacobian. Returns the
    solution and the Jacobian of the voltage residuals (V) there.
    """
    (a, b), *_ = np.linalg.lstsq(basis, measured, rcond=None)
    rho0 = float(np.clip(a + b, 1e-3, 1.0))
    f0 = float(np.clip(a / (a + b), 0.0, 1.0)) if a + b > 0 else 0.5

    def coupling(p):
        rho, f = p
        return rho * (f * basis[:, 0] + (1.0 - f) * basis[:, 1])

    def residual(p):
        return slope_v * (measured - coupling(p))  # modelled minus measured voltage

    def jacobian(p):
        rho, f = p
        shape = f * basis[:, 0] + (1.0 - f) * basis[:, 1]
        return -slope_v * np.column_stack([shape, rho * (basis[:, 0] - basis[:, 1])])

    result = least_squares(
        residual, [rho0, f0], jac=jacobian, bounds=([1e-6, 0.0], [1.0, 1.0]), xtol=1e-12
    )
    return result.x, jacobian(result.x)


def _covariance(jac, variance):
    """``variance (JᵀJ)⁻¹``; infinite where JᵀJ is singular."""
    try:
        return variance * np.linalg.inv(jac.T @ jac)
    except np.linalg.LinAlgError:
        return np.full((2, 2), np.inf)


def _readings(distance_mm, volts, model, clamp_margin_v):
    """The readings that carry the coupling, checked: distances, voltages (mm, V), the mask."""
    d = np.asarray(distance_mm, dtype=float)
    v = np.asarray(volts, dtype=float)
    if d.ndim != 1 or d.shape != v.shape:
        raise InputError("material curve: distance_mm and volts must be 1-D and of equal length")
    if not (np.all(np.isfinite(d)) and np.all(np.isfinite(v))):
        raise InputError("material curve: distances and volts must be finite numbers")
    if np.any(d <= 0):
        raise InputError("material curve: distance_mm must be positive")
    used = signal_readings(v, model, "material curve", clamp_margin_v=clamp_margin_v)
    return d[used], v[used], used


def _basis(d, model, span):
    """The mirror and Lambertian couplings at ``d`` (mm) as columns; refused if collinear."""
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
    return basis


def _summary(f):
    """Title and (label, value) rows of :class:`MaterialFit`."""
    rows = [
        ("reflectance ρ", f"{fmt(f.reflectance)} ± {fmt(f.reflectance_sigma, 2)}"),
        (
            "specular fraction f",
            f"{fmt(f.specular_fraction)} ± {fmt(f.specular_fraction_sigma, 2)}",
        ),
        ("correlation of ρ and f", fmt(f.correlation)),
        ("RMS residual", fmt(f.rms_residual_v, unit="V")),
        ("max residual", fmt(f.max_residual_v, unit="V")),
        ("readings used", f"{f.points} ({f.clamped} clamped left out)"),
    ]
    return "MaterialFit", rows
