"""Closed-form couplings of a sensor facing a flat target: one Hankel integral per distance.

On a flat target square to the sensor every quantity of the light path is a function of the
distance r from the axis, and the couplings reduce to one integral over the spatial
frequency k (the Hankel transform of order 0 of each radial factor; a 2-D convolution is the
product of the transforms). A ray leaving an emitter point with slope s reaches the plane at
distance D a distance D·s away, so the irradiance of a point source there is q(x/D)/D², with
q the density of the ray slopes; the die spreads the points as a Gaussian of 1/e radius ω0:

* the beam's transform ``Ê_D(k) = Q(k D) · exp(−k² ω0²/4)``, Q the transform of q
  (Q(0) = 1): ``exp(−k² T²/4)`` for the fast model's Gaussian slopes (T = tan θ), the sum of
  two for ``"two_gaussian"``, and for ``"cosine_power"`` (q ∝ (1 + s²)^−(m+3)/2,
  :func:`~reflector_opt.model._exact_model_form.cosine_power_exponent`)
  ``Q(u) = u^μ K_μ(u) / (2^(μ−1) Γ(μ))`` with μ = (m + 1)/2 (Gradshteyn and Ryzhik 6.565.4);
* the mirror part: the image of the emitter at 2d, seen on the detector disc of radius a at
  offset e: ``η_M = S/(2π) ∫ Ê_2d(k) J0(k e) D_a(k) k dk``, ``D_a(k) = 2 J1(k a)/(k a)`` the
  disc's mean;
* the Lambertian part: radiance E/π seen at cos·cos/r² from height d, whose radial factor
  d²/(d² + r²)² has the transform π k d K1(k d) (Gradshteyn and Ryzhik 6.565.4 with ν = 1):
  ``η_L = S/(2π) ∫ Ê_d(k) · k d K1(k d) · J0(k e) D_a(k) k dk``;
* sub-surface spread, the kernel exp(−r/ℓ)/(2πℓ²) of
  :mod:`~reflector_opt.model._exact_model_form` convolved with the irradiance, multiplies the
  Lambertian integrand by its transform ``(1 + k² ℓ²)^−3/2``.

The integrals run over k in [0, 14/w] (w the beam's 1/e radius at the plane; the Gaussian
factor is e⁻⁴⁹ there) on :data:`NODES` Gauss–Legendre nodes. Against the exact reference
(:func:`reflector_opt.model._exact_model_form.exact_model_form_coupling` on a sphere of 10⁵ mm) both
parts agree to 2·10⁻⁴ for the Gaussian beam and to 2·10⁻³ for the other patterns from
0.3 mm on (tests/model/test_flat_hankel.py) — closer than the compiled kernel's own rules on
a flat target. :mod:`reflector_opt.model._material_fit` uses the ratios: the spread's effect
on the Lambertian part and another emitter pattern's effect on both parts.
"""

import functools

import numpy as np
from scipy.special import gammaln, j0, j1, k1e, kve

from reflector_opt.model._exact_model_form import (
    check_options,
    cosine_power_exponent,
    two_gaussian_slopes,
)
from reflector_opt.model._surface import SurfaceCoupling

#: Gauss–Legendre nodes of each integral over k.
NODES = 128
#: The integrals stop at this many over the beam's 1/e radius, 1/mm per 1/mm.
_K_SPAN = 14.0


def slope_transform(k, divergence_deg, pattern="gaussian"):
    """2-D Fourier transform Q(k) of an emitter's density of ray slopes, Q(0) = 1.

    Parameters
    ----------
    k : array_like
        Spatial frequency in slope units (k·D at a plane D away), dimensionless, ≥ 0.
    divergence_deg : float
        The pattern's nominal 1/e half-angle θ, degrees.
    pattern : str
        One of :data:`~reflector_opt.model._exact_model_form.EMITTER_PATTERNS`.

    Returns
    -------
    numpy.ndarray
        Q at each k, shape of ``k``.
    """
    k = np.asarray(k, dtype=float)
    if pattern == "cosine_power":
        mu = 0.5 * (cosine_power_exponent(divergence_deg) + 1.0)
        u = np.maximum(k, 1e-12)
        log_q = mu * np.log(u) + np.log(kve(mu, u)) - u - (mu - 1.0) * np.log(2.0) - gammaln(mu)
        return np.where(k > 0, np.exp(log_q), 1.0)
    if pattern == "two_gaussian":
        shares, widths = two_gaussian_slopes(divergence_deg)
    else:
        check_options(0.0, 0.0, pattern)
        shares, widths = np.ones(1), np.tan(np.deg2rad([divergence_deg]))
    return sum(c * np.exp(-((k * w) ** 2) / 4.0) for c, w in zip(shares, widths, strict=True))


def flat_couplings(distance_mm, model, *, emitter_pattern="gaussian", subsurface_mm=0.0):
    """Mirror and Lambertian couplings of a flat target square to the sensor, closed form.

    ``η_M(d)`` and ``η_L(d)`` of the module notes, each for a surface of reflectance 1, so
    that ``η = ρ · [f · η_M + (1 − f) · η_L]``
    (:meth:`~reflector_opt.model._surface.SurfaceCoupling.total`).

    Parameters
    ----------
    distance_mm : array_like
        Emitter-to-target distances d, mm (> 0).
    model : reflector_opt.model._sensors.SensorModel
        ω0, θ, the emitter–detector offset e and the detector area S.
    emitter_pattern : str, optional
        ``"gaussian"`` (the fast model's), ``"cosine_power"`` or ``"two_gaussian"``.
    subsurface_mm : float, optional
        Length ℓ of the sub-surface spread of the Lambertian part, mm (0: none).

    Returns
    -------
    SurfaceCoupling
        Arrays of the shape of ``distance_mm``.
    """
    check_options(0.0, subsurface_mm, emitter_pattern)
    d = np.asarray(distance_mm, dtype=float)
    flat = d.reshape(-1, 1)
    mirror = _integral(2.0 * flat, model, emitter_pattern, None)
    lambertian = _integral(flat, model, emitter_pattern, (flat, float(subsurface_mm)))
    return SurfaceCoupling(mirror=mirror.reshape(d.shape), lambertian=lambertian.reshape(d.shape))


def subsurface_ratio(distance_mm, model, subsurface_mm, emitter_pattern="gaussian"):
    """Lambertian coupling with sub-surface spread over that without, on a flat target.

    Parameters
    ----------
    distance_mm : array_like
        Distances d, mm.
    model : reflector_opt.model._sensors.SensorModel
    subsurface_mm : float
        Spread length ℓ, mm (0 gives 1).
    emitter_pattern : str, optional
        The emitter's pattern.

    Returns
    -------
    numpy.ndarray
        ``η_L(d; ℓ) / η_L(d; 0)``, shape of ``distance_mm``.
    """
    d = np.asarray(distance_mm, dtype=float)
    if subsurface_mm == 0.0:
        return np.ones(d.shape)
    check_options(0.0, subsurface_mm, emitter_pattern)
    flat = d.reshape(-1, 1)
    spread = _integral(flat, model, emitter_pattern, (flat, float(subsurface_mm)))
    plain = _integral(flat, model, emitter_pattern, (flat, 0.0))
    return (spread / plain).reshape(d.shape)


@functools.lru_cache(maxsize=4)
def _nodes(n):
    """Gauss–Legendre nodes and weights on [−1, 1] (computed once per order)."""
    return np.polynomial.legendre.leggauss(n)


def _integral(plane_mm, model, pattern, lambertian):
    """``S/(2π) ∫ Ê_D(k) g(k) J0(k e) D_a(k) k dk`` for planes at ``plane_mm`` (n, 1), with
    g = 1 (mirror) or, for ``lambertian = (d, ℓ)``, the Lambertian factor and the spread."""
    slope = np.tan(np.deg2rad(model.divergence_deg))
    radius = model.source_radius_mm
    width = np.sqrt(radius**2 + (plane_mm * slope) ** 2)
    t, w = _nodes(NODES)
    k_max = _K_SPAN / width
    k = 0.5 * (t + 1.0) * k_max
    weight = 0.5 * w * k_max
    a = np.sqrt(model.detector_area_mm2 / np.pi)
    disc = 2.0 * j1(k * a) / (k * a)
    beam = slope_transform(k * plane_mm, model.divergence_deg, pattern)
    beam = beam * np.exp(-((k * radius) ** 2) / 4.0)
    factor = 1.0
    if lambertian is not None:
        d, length = lambertian
        factor = (k * d) * k1e(k * d) * np.exp(-k * d) * (1.0 + (k * length) ** 2) ** -1.5
    integrand = beam * factor * j0(k * model.emitter_detector_mm) * disc * k
    return model.detector_area_mm2 / (2.0 * np.pi) * np.sum(integrand * weight, axis=-1)
