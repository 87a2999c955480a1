"""The exact reference extended by physics the fast model leaves out (model-form error).

:mod:`reflector_opt.model._exact` computes the fast model's own physics exactly: a Gaussian
emitter, a perfect mirror part and a Lambertian part. A printed unit has more than that, and a
calibration or identification validated only against the model's own physics cannot show what
the rest costs. This module computes the same couplings (detected over emitted power, surface
of reflectance 1, mirror-like and diffuse share apart) with three optical effects the fast
model lacks, each a named option whose zero recovers
:func:`~reflector_opt.model._exact.exact_coupling` (docs/model.md, "Physics the fast model
leaves out"):

* **Rough specular lobe** (``roughness_deg``): the mirror-like share is reflected by a
  Cook–Torrance microfacet surface, ``f_r = D(h) / (4 cos i cos o)`` with the Beckmann
  distribution of microfacet normals ``D(h) = exp(−tan²θ_h / m²) / (π m² cos⁴θ_h)``,
  m = tan(``roughness_deg``) the RMS slope of the surface (Beckmann and Spizzichino, *The
  Scattering of Electromagnetic Waves from Rough Surfaces*, 1963; Cook and Torrance, ACM TOG
  1(1), 1982; Walter et al., EGSR 2007). D is normalised in projected area,
  ``∫ D(h) cos θ_h dω_h = 1``, so for an isotropic D the lobe returns all the light it
  receives, like the mirror (shadowing, masking and the Fresnel factor are left out: the share
  f carries the Fresnel reflection, and with slopes of a few degrees at incidences below 60°
  the Smith shadowing is within 10⁻³ of 1). A point x lit by the emitter and seen by the
  detector point y contributes ``I(P − x) D(h) cos ψ / (4 |P − x|² |y − P|²) dA`` — the
  cosines of the BRDF cancel the projected irradiance and radiance. The lobe is narrow on the
  surface (tens of µm), so it is integrated per emitter/detector pair about the pair's exact
  specular point: Gauss–Hermite in the microfacet slope, mapped to the surface through the
  slope's Jacobian there (finite differences), with the exact integrand at every node. As
  m → 0 this is the ray tube of the mirror.
* **Sub-surface spread** (``subsurface_mm``): white resin is translucent; light entering at
  P' leaves from points P around it. The diffuse part's radiance is formed from the blurred
  irradiance ``E'(P) = ∫ K(|P − P'|) E(P') dA'`` with the exponential kernel
  ``K(r) = exp(−r/ℓ) / (2π ℓ²)`` (unit integral over the plane; the r-weighted radial
  density is Gamma(2, ℓ), mean distance 2ℓ): a simple stand-in for the diffusion dipole's
  radial profile (Jensen et al., SIGGRAPH 2001), whose far tail decays as exp(−σ_tr r)/r.
  The kernel is applied with generalised Gauss–Laguerre nodes (weight r·e^{−r/ℓ}) in the
  geodesic distance and uniform nodes in direction, its weights summing to 1: the light is
  conserved and only moved (what moves beyond the visible part is not seen). The irradiance
  is evaluated directly at the spread points, not interpolated from the cap's grid.
* **Emitter pattern** (``emitter_pattern``), the LED's angular distribution, with the same
  Gaussian distribution of points over the die:

  - ``"gaussian"``: the fast model's Gaussian density of ray slopes, ``q(s) = exp(−|s|²/T²) /
    (π T²)``, T = tan θ, radiant intensity ``q(s)/cos³γ``;
  - ``"cosine_power"``: a generalised Lambertian LED, ``I(γ) = (m + 1) cosᵐγ / (2π)``
    (Moreno and Sun, Opt. Express 16(3), 2008) with cosᵐθ = 1/e at the model's 1/e angle θ,
    ``m = −1 / ln cos θ`` (6.6 for θ = 30.8°). Its mean-square ray slope, 2/(m − 1), then
    equals T² to O(T⁴) (within 1 % here): the same nominal width and the same RMS spot radius
    ω(d) as the Gaussian, with a sharper peak (35 % more on the axis) and longer wings;
  - ``"two_gaussian"``: a narrow core and a wide halo, ``q = c q(T₁) + (1 − c) q(T₂)`` with
    c = 0.7, T₁ = 0.8 T and T₂ chosen so that the mean-square slope is T² again
    (T₂ = 1.36 T): the same RMS spot radius, with a lensed LED's core and its halo.

The quadrature shares the Gauss rules of :mod:`reflector_opt.model._exact` (emitter, detector
and lit cap); tests/model/test_exact_model_form.py checks every limit against it, the rough
lobe against a brute-force quadrature over the surface and a flat-target closed form, and
the spread against the convolution of a flat closed form.
"""

import numpy as np
from scipy.special import roots_genlaguerre

from reflector_opt.model._exact import (
    DEFAULT_ORDERS,
    design_couplings,
    gauss_hermite_2d,
    lambertian_detected,
    lit_cap,
    mirror,
    sensor_nodes,
    specular_points,
    sphere_rule,
)
from reflector_opt.model._geometry import unit, unit_perpendicular
from reflector_opt.model._surface import SurfaceCoupling
from reflector_opt.util._errors import InputError

#: Names of the emitter's angular patterns (module notes).
EMITTER_PATTERNS = ("gaussian", "cosine_power", "two_gaussian")

#: The two-Gaussian pattern's core: its share of the power and its slope width over T.
TWO_GAUSSIAN_CORE = (0.7, 0.8)

#: Gauss–Hermite nodes per axis in the microfacet slope, per emitter/detector pair.
LOBE_ORDER = 4

#: Generalised Gauss–Laguerre nodes in distance × uniform directions of the spread kernel.
SPREAD_ORDER = (4, 8)

#: Largest RMS slope angle of the rough lobe, degrees (beyond it the lobe is no longer a
#: specular lobe and the slope-Jacobian mapping loses accuracy).
MAX_ROUGHNESS_DEG = 20.0

#: Largest spread length, mm (several times the printed parts' transport length).
MAX_SUBSURFACE_MM = 1.0


def check_options(roughness_deg, subsurface_mm, emitter_pattern):
    """Check the optical options and return them as (float, float, str).

    Parameters
    ----------
    roughness_deg : float
        RMS microfacet slope angle, degrees, 0 to :data:`MAX_ROUGHNESS_DEG`.
    subsurface_mm : float
        Spread length ℓ, mm, 0 to :data:`MAX_SUBSURFACE_MM`.
    emitter_pattern : str
        One of :data:`EMITTER_PATTERNS`.

    Returns
    -------
    tuple
        Raises :class:`~reflector_opt.util._errors.InputError` naming the bad option.
    """
    roughness = float(roughness_deg)
    if not 0.0 <= roughness <= MAX_ROUGHNESS_DEG:
        raise InputError(
            f"roughness_deg: expected 0 to {MAX_ROUGHNESS_DEG:g}°, got {roughness_deg!r}"
        )
    spread = float(subsurface_mm)
    if not 0.0 <= spread <= MAX_SUBSURFACE_MM:
        raise InputError(
            f"subsurface_mm: expected 0 to {MAX_SUBSURFACE_MM:g} mm, got {subsurface_mm!r}"
        )
    if emitter_pattern not in EMITTER_PATTERNS:
        raise InputError(
            f"emitter_pattern: expected one of {', '.join(EMITTER_PATTERNS)}, "
            f"got {emitter_pattern!r}"
        )
    return roughness, spread, emitter_pattern


def cosine_power_exponent(divergence_deg):
    """Exponent m of the cosine-power pattern with cosᵐθ = 1/e at the 1/e angle θ.

    ``m = −1 / ln cos θ``. The pattern's mean-square ray slope is 2/(m − 1), equal to tan²θ
    (the Gaussian model's) to O(tan⁴θ).

    Parameters
    ----------
    divergence_deg : float
        1/e half-angle θ, degrees (0 < θ < 90).

    Returns
    -------
    float
    """
    return -1.0 / np.log(np.cos(np.deg2rad(divergence_deg)))


def two_gaussian_slopes(divergence_deg):
    """Shares and slope widths (1/e) of the two-Gaussian pattern.

    The core holds ``TWO_GAUSSIAN_CORE[0]`` of the power with width ``TWO_GAUSSIAN_CORE[1]·T``;
    the halo's width makes the mean-square slope c T₁² + (1 − c) T₂² equal T², T = tan θ.

    Parameters
    ----------
    divergence_deg : float
        1/e half-angle θ of the model's Gaussian, degrees.

    Returns
    -------
    tuple of (numpy.ndarray, numpy.ndarray)
        Shares (2,) summing to 1 and slope widths (2,) (dimensionless).
    """
    share, ratio = TWO_GAUSSIAN_CORE
    slope = np.tan(np.deg2rad(divergence_deg))
    halo = slope * np.sqrt((1.0 - share * ratio**2) / (1.0 - share))
    return np.array([share, 1.0 - share]), np.array([ratio * slope, halo])


def emitter_intensity(direction, axis, divergence_deg, pattern="gaussian"):
    """Radiant intensity of one emitter point per unit emitted power, W/sr per W.

    Parameters
    ----------
    direction : array_like, shape (..., 3)
        Unit directions of the rays.
    axis : array_like, shape (3,)
        The emitter's optical axis.
    divergence_deg : float
        The model's 1/e half-angle θ, degrees.
    pattern : str
        One of :data:`EMITTER_PATTERNS` (module notes give each formula).

    Returns
    -------
    numpy.ndarray
        Shape ``(...)``; 0 behind the emitter. Each pattern integrates to 1 over the
        hemisphere.
    """
    v = np.asarray(direction, dtype=float)
    a = unit(np.asarray(axis, dtype=float))
    along = v @ a
    ok = along > 0.0
    c = np.where(ok, along, 1.0)
    if pattern == "cosine_power":
        m = cosine_power_exponent(divergence_deg)
        value = (m + 1.0) / (2.0 * np.pi) * c**m
    else:
        if pattern == "gaussian":
            shares, widths = np.ones(1), np.tan(np.deg2rad([divergence_deg]))
        elif pattern == "two_gaussian":
            shares, widths = two_gaussian_slopes(divergence_deg)
        else:
            raise InputError(f"emitter_pattern: unknown pattern {pattern!r}")
        s_sq = np.maximum(1.0 - c * c, 0.0) / (c * c)
        q = sum(
            share * np.exp(-s_sq / width**2) / (np.pi * width**2)
            for share, width in zip(shares, widths, strict=True)
        )
        value = q / c**3
    return np.where(ok, value, 0.0)


def _widest_slope(divergence_deg, pattern):
    """A slope width that bounds the beam for the lit cap (7 widths: negligible beyond)."""
    slope = np.tan(np.deg2rad(divergence_deg))
    if pattern == "two_gaussian":
        return float(two_gaussian_slopes(divergence_deg)[1].max())
    if pattern == "cosine_power":
        return 1.2 * slope  # (1 + s²)^(−(m+3)/2) is below 1e-6 of the peak at 7 T
    return slope


def _lobe_geometry(offset, src, det, centre, radius, n0, t1, t2):
    """Surface points at tangent-plane offsets about the specular points, and their slopes.

    ``offset`` (..., K, 2) in mm along (t1, t2) of each pair's specular point; the point is
    the gnomonic projection onto the sphere. Returns the microfacet slope of the half vector
    relative to the local normal, (..., K, 2), and the pieces of the integrand.
    """
    normal = unit(
        n0[..., None, :]
        + (offset[..., :1] * t1[..., None, :] + offset[..., 1:] * t2[..., None, :]) / radius
    )
    point = centre + radius * normal
    to_source = src[..., None, :] - point
    to_detector = det[..., None, :] - point
    r1 = np.linalg.norm(to_source, axis=-1)
    r2 = np.linalg.norm(to_detector, axis=-1)
    d1 = to_source / r1[..., None]
    d2 = to_detector / r2[..., None]
    half = unit(d1 + d2)
    tangent = t1[..., None, :] - np.sum(t1[..., None, :] * normal, -1, keepdims=True) * normal
    e1 = unit(tangent)
    e2 = np.cross(normal, e1)
    c = np.sum(half * normal, -1)
    safe = np.where(c > 0.0, c, 1.0)
    slope = np.stack([np.sum(half * e1, -1), np.sum(half * e2, -1)], -1) / safe[..., None]
    cos_in = np.sum(d1 * normal, -1)
    cos_out = np.sum(d2 * normal, -1)
    return slope, c, r1, r2, d1, d2, cos_in, cos_out


def _rough(sources, detectors, source_w, detector_w, centre, radius, a, w, intensity, m, order):
    """The Beckmann microfacet lobe, integrated about each pair's specular point."""
    src = np.broadcast_to(sources[:, None, :], (len(sources), len(detectors), 3))
    det = np.broadcast_to(detectors[None, :, :], src.shape)
    p0, n0 = specular_points(src, det, centre, radius)
    t1 = unit(np.cross(n0, w))
    t2 = np.cross(n0, t1)
    args = (src, det, centre, radius, n0, t1, t2)
    # Jacobian of the slope against the tangent-plane offset at the specular point, by
    # central differences a step 1e-5 of the shorter length (path or radius) wide
    reach = np.minimum(np.linalg.norm(src - p0, axis=-1), np.linalg.norm(det - p0, axis=-1))
    step = 1e-5 * np.minimum(reach, radius)[..., None, None]
    probes = step * np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    s = _lobe_geometry(probes, *args)[0]
    jac = np.stack([s[..., 0, :] - s[..., 1, :], s[..., 2, :] - s[..., 3, :]], -1) / (2.0 * step)
    det_jac = np.abs(np.linalg.det(jac))
    regular = det_jac > 1e-12
    jac = np.where(regular[..., None, None], jac, np.eye(2))
    det_jac = np.where(regular, det_jac, 1.0)
    nodes, weights = gauss_hermite_2d(order, m)
    offset = np.einsum("...ij,kj->...ki", np.linalg.inv(jac), nodes)  # u_k = A⁻¹ s_k
    slope, c, r1, r2, d1, d2, cos_in, cos_out = _lobe_geometry(offset, *args)
    cos_psi = -(d2 @ a)
    valid = (c > 0.0) & (cos_in > 0.0) & (cos_out > 0.0) & (cos_psi > 0.0)
    c = np.where(valid, c, 1.0)
    # D(h) over the Gauss weight at the node: exp(−(|s(u)|² − |s_k|²)/m²) / cos⁴θ_h
    ratio = np.exp(-(np.sum(slope**2, -1) - np.sum(nodes**2, -1)) / m**2) / c**4
    area = (1.0 + np.sum(offset**2, -1) / radius**2) ** -1.5  # gnomonic area element
    value = intensity(-d1) / r1**2 * 0.25 * ratio * cos_psi / r2**2 * area
    value = np.where(valid, value, 0.0) @ weights / det_jac
    return source_w @ np.where(regular, value, 0.0) @ detector_w


def _spread_points(point, normal, centre, radius, length, order):
    """Points (N, J·K, 3) around each point at geodesic distances drawn from the kernel, weights."""
    rings, directions = order
    x, wx = roots_genlaguerre(rings, 1.0)
    wx = wx / wx.sum()  # Γ(2) = 1 up to round-off: the kernel moves light, never makes it
    b1 = unit_perpendicular(normal)
    b2 = np.cross(normal, b1)
    stagger = 0.5 * (np.arange(rings) % 2)
    phi = 2.0 * np.pi * (np.arange(directions)[None, :] + stagger[:, None]) / directions
    angle = (length * x / radius)[:, None] * np.ones_like(phi)  # geodesic distance / R
    sideways = (
        np.cos(phi).ravel()[None, :, None] * b1[:, None, :]
        + np.sin(phi).ravel()[None, :, None] * b2[:, None, :]
    )
    moved = (
        np.cos(angle).ravel()[None, :, None] * normal[:, None, :]
        + np.sin(angle).ravel()[None, :, None] * sideways
    )
    weights = np.repeat(wx, directions) / directions
    return centre + radius * moved, moved, weights


def _diffuse(
    sources,
    detectors,
    source_w,
    detector_w,
    centre,
    radius,
    a,
    intensity,
    slope,
    sphere_order,
    length,
    spread_order,
):
    """The Lambertian part with the irradiance spread by the sub-surface kernel."""
    pole, cap = lit_cap(sources.mean(0), a, centre, radius, slope)
    point, normal, area = sphere_rule(centre, radius, pole, cap, *sphere_order)
    if length > 0.0:
        entry, entry_normal, kernel = _spread_points(
            point, normal, centre, radius, length, spread_order
        )
    else:
        entry, entry_normal, kernel = point[:, None, :], normal[:, None, :], np.ones(1)
    irradiance = np.zeros(len(point))
    for x, weight in zip(sources, source_w, strict=True):
        to_source = x - entry
        r = np.linalg.norm(to_source, axis=-1)
        cos_in = np.maximum(np.sum(entry_normal * to_source, -1) / r, 0.0)
        irradiance += weight * ((intensity(-to_source / r[..., None]) * cos_in / r**2) @ kernel)
    return lambertian_detected(irradiance, point, normal, area, detectors, detector_w, a)


def exact_model_form_coupling(
    sensor_mm,
    axis,
    detector_offset_mm,
    sphere_centre_mm,
    radius_mm,
    model,
    *,
    roughness_deg=0.0,
    subsurface_mm=0.0,
    emitter_pattern="gaussian",
    source_order=DEFAULT_ORDERS["source"],
    detector_order=DEFAULT_ORDERS["detector"],
    sphere_order=DEFAULT_ORDERS["sphere"],
    lobe_order=LOBE_ORDER,
    spread_order=SPREAD_ORDER,
):
    """Specular and diffuse couplings of one sensor at one pose with the extra physics.

    With every option at its zero (``roughness_deg=0``, ``subsurface_mm=0``,
    ``emitter_pattern="gaussian"``) this is :func:`reflector_opt.model._exact.exact_coupling`.

    Parameters
    ----------
    sensor_mm, axis, detector_offset_mm, sphere_centre_mm, radius_mm, model
        As :func:`reflector_opt.model._exact.exact_coupling` (mm; the axis a unit vector).
    roughness_deg : float
        RMS microfacet slope angle of the specular lobe, degrees; m = tan of it is
        Beckmann's RMS slope. 0 is the perfect mirror.
    subsurface_mm : float
        Length ℓ of the sub-surface spread kernel exp(−r/ℓ)/(2πℓ²), mm. 0 is no spread.
    emitter_pattern : str
        ``"gaussian"`` (the fast model's), ``"cosine_power"`` or ``"two_gaussian"``.
    source_order, detector_order, sphere_order
        Quadrature orders, as :func:`~reflector_opt.model._exact.exact_coupling`.
    lobe_order : int
        Gauss–Hermite nodes per slope axis of the lobe, per emitter/detector pair.
    spread_order : (int, int)
        Distances (generalised Gauss–Laguerre) and directions of the spread kernel.

    Returns
    -------
    SurfaceCoupling
        ``mirror``: the specular share's coupling (the rough lobe when ``roughness_deg`` > 0);
        ``lambertian``: the diffuse share's (spread when ``subsurface_mm`` > 0); both for
        reflectance 1, detected over emitted power.
    """
    roughness, length, pattern = check_options(roughness_deg, subsurface_mm, emitter_pattern)
    f = np.asarray(sensor_mm, dtype=float)
    centre = np.asarray(sphere_centre_mm, dtype=float)
    (a, _, w), sources, src_w, detectors, det_w = sensor_nodes(
        f, axis, detector_offset_mm, model, source_order, detector_order
    )
    if np.linalg.norm(f - centre) <= radius_mm:
        return SurfaceCoupling(mirror=0.0, lambertian=0.0)

    def intensity(direction):
        return emitter_intensity(direction, a, model.divergence_deg, pattern)

    common = (sources, detectors, src_w, det_w, centre, radius_mm, a)
    if roughness > 0.0:
        specular = _rough(*common, w, intensity, np.tan(np.deg2rad(roughness)), lobe_order)
    else:
        specular = mirror(*common, intensity)
    slope = _widest_slope(model.divergence_deg, pattern)
    diffuse = _diffuse(*common, intensity, slope, sphere_order, length, spread_order)
    area = model.detector_area_mm2
    return SurfaceCoupling(mirror=area * float(specular), lambertian=area * float(diffuse))


def exact_model_form_design_coupling(
    design,
    pitch_deg,
    roll_deg,
    *,
    roughness_deg=0.0,
    subsurface_mm=0.0,
    emitter_pattern="gaussian",
    **orders,
):
    """Extended couplings of every sensor of a design at a few poses.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    pitch_deg, roll_deg : array_like
        Pose angles, degrees, broadcast to shape P.
    roughness_deg, subsurface_mm, emitter_pattern
        The options of :func:`exact_model_form_coupling` (degrees, mm, name).
    **orders
        Quadrature orders passed to :func:`exact_model_form_coupling`.

    Returns
    -------
    SurfaceCoupling
        Arrays of shape ``P + (n_sensors,)``: the specular and diffuse shares' couplings,
        reflectance 1.
    """
    checked = check_options(roughness_deg, subsurface_mm, emitter_pattern)
    options = dict(zip(("roughness_deg", "subsurface_mm", "emitter_pattern"), checked, strict=True))
    return design_couplings(
        exact_model_form_coupling, design, pitch_deg, roll_deg, **options, **orders
    )
