"""Joint least squares of flat-target curves: the sensor, each curve's offset, a sample's surface.

A reading of a sensor facing a flat target at distance d is (docs/model.md, "Measuring the
material")::

    V = Vcc − R2 · (G · I_F · η(d) + I_dark) + c
    η(d) = ρ · [f · η_M(d) + (1 − f) · η_L(d) · R(d; ℓ)]

:meth:`~reflector_opt.model._sensors.SensorModel.output_voltage` of η plus c. The read-out's
gain acts on the collector current — it is the lumped gain G — so it scales the light and
not the supply; the offset c, one per curve, lumps the read-out's offset with every constant
coupling of the session (in-package crosstalk, ambient light, dark current). η_M and η_L are
the compiled model's flat-target couplings
(:func:`~reflector_opt.model._optics.flat_target_coupling`), R the sub-surface spread of the
diffuse share (:func:`~reflector_opt.model._flat_hankel.subsurface_ratio`, 1 for ℓ = 0).

:func:`fit_flat_curves` fits, to one or more curves of the same sensor, the sensor's ω0, θ
and G (or holds them), each curve's c, and — for the one curve whose target is the sample —
ρ, f and ℓ, the known targets' (ρ, f) given and their ℓ taken as 0 (an opaque reference).
``scipy.optimize.least_squares`` (trust-region reflective) keeps every parameter in its
physical range: ω0, θ and G positive (fitted in logs), ρ in (0, 1], f in [0, 1], ℓ in
[0, 1] mm. The Jacobian is by forward differences, the compiled couplings cached per beam so
that only ω0 and θ cost a new evaluation.
"""

from collections import OrderedDict
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from reflector_opt.model._exact_model_form import MAX_SUBSURFACE_MM
from reflector_opt.model._flat_hankel import flat_couplings, subsurface_ratio
from reflector_opt.model._optics import flat_target_coupling
from reflector_opt.util._errors import InputError

_SENSOR = ("source_radius_mm", "divergence_deg", "current_gain")
_SURFACE = ("reflectance", "specular_fraction", "subsurface_sq_mm2")
#: Bounds of each parameter in the fitted vector (logs for the sensor's).
_BOUNDS = {
    "source_radius_mm": (np.log(1e-4), np.log(5.0)),
    "divergence_deg": (np.log(1e-4), np.log(89.0)),
    "current_gain": (np.log(1e-4), np.log(1e6)),
    "offset_v": (-1.0, 1.0),
    "reflectance": (1e-3, 1.0),
    "specular_fraction": (0.0, 1.0),
    "subsurface_sq_mm2": (0.0, MAX_SUBSURFACE_MM**2),
}
#: The sample's surface bounds of a sensitivity refit (:func:`refit_with_pattern`): wide, so
#: that a shift is the estimator's and not cut at a physical bound.
_RELAXED = {"reflectance": (1e-3, 2.0), "specular_fraction": (-1.0, 2.0)}
#: Typical change of each kind of fitted parameter, the least squares' ``x_scale``.
_SCALE = {"log": 1.0, "offset_v": 0.01, "surface": 0.1}
#: Forward-difference step of each kind of fitted parameter (in its fitted unit).
_STEP = {"log": 1e-6, "offset_v": 1e-6, "surface": 1e-7}


@dataclass(frozen=True)
class FlatCurve:
    """One curve's readings against a flat target.

    Attributes
    ----------
    distance_mm, volts : numpy.ndarray
        Distances (mm) and output voltages (V) of the readings to fit (none clamped).
    reflectance, specular_fraction : float or None
        The target's ρ and f if known (a reference), None for the sample whose surface is
        fitted.
    """

    distance_mm: np.ndarray
    volts: np.ndarray
    reflectance: float | None = None
    specular_fraction: float | None = None

    @property
    def is_sample(self):
        """True for the curve whose target's surface is fitted."""
        return self.reflectance is None


@dataclass(frozen=True)
class FlatSolution:
    """Result of :func:`fit_flat_curves`.

    Attributes
    ----------
    names : tuple of str
        The fitted parameters: the sensor's (``source_radius_mm``, ``divergence_deg``,
        ``current_gain``) when fitted, ``offset_v_0``, … per curve, and the sample's
        ``reflectance``, ``specular_fraction`` and ``subsurface_sq_mm2``, the square of the
        spread length ℓ (when fitted; the curve depends on ℓ² at first order, so ℓ² is fitted
        and bounded at 0 with a regular covariance).
    values : numpy.ndarray
        Their values (mm, degrees, dimensionless, V).
    covariance : numpy.ndarray
        Their covariance ``s² (JᵀJ)⁻¹``, s² the residual variance over n − k degrees of
        freedom but at least σ_V²; infinite where the data leave a direction undetermined.
    model : reflector_opt.model._sensors.SensorModel
        The sensor at the solution.
    residuals_v : tuple of numpy.ndarray
        Model minus measured voltage of each curve, V.
    """

    names: tuple
    values: np.ndarray
    covariance: np.ndarray
    model: object
    residuals_v: tuple

    def value(self, name):
        """A fitted parameter's value."""
        return float(self.values[self.names.index(name)])

    def sigma(self, name):
        """A fitted parameter's standard deviation."""
        i = self.names.index(name)
        return float(np.sqrt(self.covariance[i, i]))


def fit_flat_curves(
    curves, model, *, fit_sensor=True, fit_offsets=True, subsurface=True, sigma_v=0.002, start=None
):
    """Fit a sensor, each curve's offset and a flat sample's surface to flat-target curves.

    The model and the bounds are the module notes'.

    Parameters
    ----------
    curves : sequence of FlatCurve
        Curves of one sensor; at most one of them the sample (``reflectance`` None).
    model : reflector_opt.model._sensors.SensorModel
        The sensor: the start of ω0, θ and G when ``fit_sensor``, else held as given; its
        emitter–detector offset, detector area and circuit are always held.
    fit_sensor : bool, optional
        Fit ω0, θ and G (needs a curve of a known target).
    fit_offsets : bool, optional
        Fit each curve's offset c (else c = 0).
    subsurface : bool, optional
        Fit the sample's sub-surface spread ℓ (else ℓ = 0).
    sigma_v : float, optional
        RMS noise of a reading, V: the least residual scatter the covariance assumes.
    start : FlatSolution, optional
        A solution of the same problem to start from (default: the known targets' curves
        fitted first, then the sample's ρ, f and offset by linear least squares).

    Returns
    -------
    FlatSolution

    Raises
    ------
    InputError
        No curve; more than one sample; the sensor fitted without a known target; a fit
        that does not converge.
    """
    problem = _FlatProblem(tuple(curves), model, fit_sensor, fit_offsets, subsurface)
    z0 = _start(problem, sigma_v) if start is None else problem.to_fitted(start.values)
    return _solve(problem, z0, sigma_v)


def refit_with_pattern(curves, at, pattern, model, **options):
    """Fit again the curves a sensor with another LED pattern would give.

    The curves :func:`fit_flat_curves` models at the parameter values ``at``, each part
    scaled by the closed-form coupling of ``pattern`` over the Gaussian's
    (:func:`~reflector_opt.model._flat_hankel.flat_couplings`), fitted from ``at`` with the
    Gaussian model: the solution's departure from ``at`` is what that pattern does to the
    estimate there. The sample's ρ and f may leave their physical range in this fit (ρ up to
    2, f from −1 to 2): the shift measures the estimator's sensitivity, which a bound would
    cut.

    Parameters
    ----------
    curves : sequence of FlatCurve
        The curves of the fit (their distances and targets are used).
    at : FlatSolution
        Parameter values (``names`` and ``values``) of the same problem.
    pattern : str
        ``"cosine_power"`` or ``"two_gaussian"``.
    model : reflector_opt.model._sensors.SensorModel
        The sensor of the fit (its held parameters).
    **options
        The options of :func:`fit_flat_curves` (``fit_sensor``, ``fit_offsets``,
        ``subsurface``, ``sigma_v``).

    Returns
    -------
    FlatSolution
    """
    flags = [options.get(k, True) for k in ("fit_sensor", "fit_offsets", "subsurface")]
    problem = _FlatProblem(tuple(curves), model, *flags)
    synthetic = np.split(problem.volts(problem.to_fitted(at.values), pattern), problem.split)
    changed = tuple(
        FlatCurve(c.distance_mm, v, c.reflectance, c.specular_fraction)
        for c, v in zip(curves, synthetic, strict=True)
    )
    relaxed = _FlatProblem(changed, model, *flags, relaxed=True)
    return _solve(relaxed, relaxed.to_fitted(at.values), options.get("sigma_v", 0.002))


def _solve(problem, z0, sigma_v):
    """The bounded least squares from z0, and its :class:`FlatSolution`."""
    lower, upper = problem.bounds()
    result = least_squares(
        problem.residuals,
        np.clip(z0, lower, upper),
        jac=lambda z: _jacobian(problem, z),
        bounds=(lower, upper),
        x_scale=np.array([_SCALE[kind] for kind in problem.kinds()]),
        xtol=1e-10,
        ftol=1e-12,
        gtol=1e-12,
        max_nfev=200,
    )
    if result.status <= 0:
        raise InputError(f"flat curves: the fit did not converge ({result.message})")
    z = result.x
    residuals = problem.residuals(z)
    # ∂residuals/∂(natural values): the log columns divided by their values
    jacobian = _jacobian(problem, z)
    jacobian[:, : problem.n_sensor] /= np.exp(z[: problem.n_sensor])
    covariance = _covariance(jacobian, residuals, sigma_v)
    return FlatSolution(
        problem.names,
        problem.natural(z),
        covariance,
        problem.sensor(z),
        tuple(np.split(residuals, problem.split)),
    )


def _covariance(jacobian, residuals, sigma_v):
    """``s² (JᵀJ)⁻¹`` with s² = max(RSS/(n − k), σ_V²); inf where JᵀJ is singular."""
    n, k = jacobian.shape
    variance = max(float(residuals @ residuals) / max(n - k, 1), sigma_v**2)
    scale = np.linalg.norm(jacobian, axis=0)
    if np.any(scale == 0.0):
        return np.full((k, k), np.inf)
    normal = (jacobian / scale).T @ (jacobian / scale)
    if np.linalg.cond(normal) > 1e14:
        return np.full((k, k), np.inf)
    return variance * np.linalg.inv(normal) / np.outer(scale, scale)


class _FlatProblem:
    """The modelled voltages of :func:`fit_flat_curves` in the fitted vector z: the sensor's
    parameters in logs, then the curves' offsets, then the sample's surface (its Jacobian:
    :func:`_jacobian`)."""

    def __init__(self, curves, model, fit_sensor, fit_offsets, subsurface, relaxed=False):
        if not curves:
            raise InputError("flat curves: no curve to fit")
        samples = [i for i, c in enumerate(curves) if c.is_sample]
        if len(samples) > 1:
            raise InputError("flat curves: at most one curve of the sample")
        if fit_sensor and len(samples) == len(curves):
            raise InputError("flat curves: fitting the sensor needs a curve of a known target")
        self.curves, self.base = curves, model
        self.sample = samples[0] if samples else None
        names = list(_SENSOR) if fit_sensor else []
        names += [f"offset_v_{i}" for i in range(len(curves))] if fit_offsets else []
        if self.sample is not None:
            names += list(_SURFACE if subsurface else _SURFACE[:2])
        self.names = tuple(names)
        self.n_sensor = 3 if fit_sensor else 0
        self.distance = np.concatenate([c.distance_mm for c in curves])
        self.measured = np.concatenate([c.volts for c in curves])
        self.split = np.cumsum([c.distance_mm.size for c in curves])[:-1]
        self._cache = OrderedDict()
        self.relaxed = relaxed

    def bounds(self):
        """Lower and upper bounds of z."""
        bounds = {**_BOUNDS, **_RELAXED} if self.relaxed else _BOUNDS
        pairs = [bounds["offset_v" if n.startswith("offset_v") else n] for n in self.names]
        return np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])

    def kinds(self):
        """Each fitted parameter's kind: ``log`` (the sensor's), ``offset_v`` or ``surface``."""
        return [
            "log" if j < self.n_sensor else "offset_v" if name.startswith("offset") else "surface"
            for j, name in enumerate(self.names)
        ]

    def natural(self, z):
        """z in natural units (ω0 mm, θ degrees, G, offsets V, ρ, f, ℓ mm)."""
        x = np.array(z, dtype=float)
        x[: self.n_sensor] = np.exp(x[: self.n_sensor])
        return x

    def to_fitted(self, values):
        """Natural values to z."""
        z = np.array(values, dtype=float)
        z[: self.n_sensor] = np.log(z[: self.n_sensor])
        return z

    def sensor(self, z):
        """The sensor model at z."""
        if not self.n_sensor:
            return self.base
        return self.base.with_(**dict(zip(_SENSOR, np.exp(z[:3]).tolist(), strict=True)))

    def _parts(self, model):
        """Kernel mirror and Lambertian couplings at every curve's distances (cached)."""
        key = (model.source_radius_mm, model.divergence_deg)
        if key not in self._cache:
            mirror = flat_target_coupling(self.distance, model, 1.0, 1.0)
            lambertian = flat_target_coupling(self.distance, model, 1.0, 0.0)
            self._cache[key] = (mirror, lambertian)
            if len(self._cache) > 8:
                self._cache.popitem(last=False)
        return self._cache[key]

    def value(self, z, name, default=0.0):
        """The fitted parameter ``name`` at z, or ``default`` where it is not fitted."""
        return float(z[self.names.index(name)]) if name in self.names else default

    def surfaces(self, z):
        """Per curve (ρ, f, ℓ) at z (ℓ in mm; a known target's is 0)."""
        ell = float(np.sqrt(self.value(z, "subsurface_sq_mm2")))
        sample = (self.value(z, "reflectance"), self.value(z, "specular_fraction"), ell)
        return [
            sample if c.is_sample else (c.reflectance, c.specular_fraction, 0.0)
            for c in self.curves
        ]

    def volts(self, z, pattern=None):
        """Modelled voltages of every curve, concatenated, V. With ``pattern`` (an emitter
        pattern of :mod:`~reflector_opt.model._flat_hankel`), each part is scaled by that
        pattern's closed-form coupling over the Gaussian's: the curves a sensor with that
        LED pattern, and the same nominal beam, would give."""
        model = self.sensor(z)
        mirror, lambertian = self._parts(model)
        eta = []
        for d, m, lam, (rho, f, ell) in zip(
            np.split(self.distance, self.split),
            np.split(mirror, self.split),
            np.split(lambertian, self.split),
            self.surfaces(z),
            strict=True,
        ):
            lam = lam * subsurface_ratio(d, model, ell) if ell > 0.0 else lam
            if pattern is not None:
                m, lam = _pattern_scaled(d, model, ell, pattern, m, lam)
            eta.append(rho * (f * m + (1.0 - f) * lam))
        offsets = [
            np.full(c.volts.size, self.value(z, f"offset_v_{i}")) for i, c in enumerate(self.curves)
        ]
        return model.output_voltage(np.concatenate(eta)) + np.concatenate(offsets)

    def residuals(self, z):
        """Modelled minus measured voltage, V."""
        return self.volts(z) - self.measured


def _jacobian(problem, z):
    """∂residuals/∂z of a :class:`_FlatProblem` by forward differences, each step away from
    the nearer bound."""
    base = problem.volts(z)
    upper = problem.bounds()[1]
    columns = np.empty((base.size, z.size))
    for j, kind in enumerate(problem.kinds()):
        h = _STEP[kind] * (1.0 + abs(z[j]))
        if z[j] + h > upper[j]:
            h = -h
        step = z.copy()
        step[j] += h
        columns[:, j] = (problem.volts(step) - base) / h
    return columns


def _pattern_scaled(d, model, ell, pattern, mirror, lambertian):
    """The parts scaled by the closed-form couplings of ``pattern`` over the Gaussian's."""
    other = flat_couplings(d, model, emitter_pattern=pattern, subsurface_mm=ell)
    gauss = flat_couplings(d, model, subsurface_mm=ell)
    return mirror * other.mirror / gauss.mirror, lambertian * other.lambertian / gauss.lambertian


def _start(problem, sigma_v):
    """A start of z: the known targets' curves fitted alone when the sensor is fitted, then
    the sample's ρ, f and offset by linear least squares with that sensor (ℓ = 0.05 mm)."""
    z = np.zeros(len(problem.names))
    model = problem.base
    n = problem.n_sensor
    z[:n] = np.log([getattr(model, k) for k in _SENSOR][:n])
    if problem.sample is None:
        return z
    known = [c for c in problem.curves if not c.is_sample]
    if n and known:
        fit_offsets = any(name.startswith("offset_v") for name in problem.names)
        first = fit_flat_curves(known, model, fit_offsets=fit_offsets, sigma_v=sigma_v)
        model = first.model
        z[:n] = np.log([getattr(model, k) for k in _SENSOR])
        offsets = iter(first.values[n:])
        for i, curve in enumerate(problem.curves):
            if not curve.is_sample and f"offset_v_{i}" in problem.names:
                z[problem.names.index(f"offset_v_{i}")] = next(offsets)
    rho, f, offset = _linear_start(problem.curves[problem.sample], model)
    if f"offset_v_{problem.sample}" in problem.names:
        z[problem.names.index(f"offset_v_{problem.sample}")] = offset
    z[problem.names.index("reflectance")] = rho
    z[problem.names.index("specular_fraction")] = f
    if "subsurface_sq_mm2" in problem.names:
        z[problem.names.index("subsurface_sq_mm2")] = 0.05**2
    return z


def _linear_start(curve, model):
    """(ρ, f, offset V) of the sample by linear least squares in V = V0 − s·η + c (s the
    circuit's slope), ρ and f moved into their bounds."""
    d = curve.distance_mm
    slope = 1.0 / (model.coupling_from_voltage(0.0) - model.coupling_from_voltage(1.0))
    basis = np.column_stack(
        [
            -slope * flat_target_coupling(d, model, 1.0, 1.0),
            -slope * flat_target_coupling(d, model, 1.0, 0.0),
            np.ones(d.size),
        ]
    )
    (a, b, offset), *_ = np.linalg.lstsq(basis, curve.volts - model.output_voltage(0.0), rcond=None)
    rho = float(np.clip(a + b, 1e-3, 1.0))
    f = float(np.clip(a / (a + b), 0.0, 1.0)) if a + b > 0 else 0.5
    return rho, f, float(np.clip(offset, -1.0, 1.0))
