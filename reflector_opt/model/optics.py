"""Reflected optical power: paper Eq 4 and its extension to a convex, tilted reflector.

Beam-radius convention: every beam radius ω here is the **1/e irradiance radius** of a
Gaussian spot, ``I(r) = P / (π ω²) · exp(−r²/ω²)``. With this convention the paper's Eq 4,
``P = P_E · S_area / (π ω²)``, is exactly the power on a small detector of area S_area at the
spot centre, and the power at a distance r from the centre carries the factor exp(−r²/ω²).

The model (docs/model.md derives it):

* the emitter is a Gaussian source of 1/e radius ω0 whose rays have Gaussian slopes of 1/e
  width tan θ about the optical axis;
* a round trip of length t out, a mirror of focal power P, and t' back has the ray-transfer
  matrix ``[[1, t'], [0, 1]] · [[1, 0], [P, 1]] · [[1, t], [0, 1]]
  = [[1 + t'P, t + t' + t t' P], [P, 1 + t'P]]``, so the returning spot has
  ``ω² = ((1 + t'P) ω0)² + ((t + t' + t t' P) tan θ)²`` (Gaussian widths add in
  quadrature). At normal incidence t' = t and P = 2/R, giving
  ``ω(d) = sqrt(((1 + 2d/R) ω0)² + (2 d tan θ (1 + d/R))²)``; a flat mirror is R → ∞;
* at incidence i the reflected axis returns to the sensor plane after t' = t / cos 2i,
  displaced by ``Δ = 2 t cos i · n⊥ / cos 2i`` (n⊥ the normal's component in the sensor
  plane); the mirror's power is 2/(R cos i) in the plane of incidence (tangential) and
  2 cos i / R across it (sagittal), so the returning beam is an astigmatic Gaussian;
* the detector sits at an offset e from the emitter; the beam's radii are taken at the
  detector's own distance down the beam, its offset from the beam axis gives the Gaussian
  factor, and the plane's obliquity to the beam the factor cos ψ · sec φ (exact for a point
  source and a flat mirror).

For a flat mirror at normal incidence (Δ = 0) the response rises and then falls with d,
peaking where ω(d) = ‖e‖: the familiar reflective-sensor curve.
"""

from __future__ import annotations

import numpy as np

from reflector_opt.model import kernel

__all__ = ["beam_radius", "coupling", "gaussian_power", "spot_displacement"]


def beam_radius(distance_mm, source_radius_mm, divergence_deg, mirror_radius_mm=np.inf):
    """1/e radius of the returning spot after a round trip to a mirror at normal incidence.

    ``ω(d) = sqrt(((1 + 2d/R) ω0)² + (2 d tan θ (1 + d/R))²)``, from the round-trip
    ray-transfer matrix ``[[1 + 2d/R, 2d(1 + d/R)], [2/R, 1 + 2d/R]]`` applied to a Gaussian
    source of radius ω0 and Gaussian slope spread tan θ. For a flat mirror (R = ∞) this is
    ``sqrt(ω0² + (2 d tan θ)²)``, the beam ω = f(d) that the paper's Eq 4 leaves open.

    Parameters
    ----------
    distance_mm : array_like
        One-way distance d from the emitter to the mirror along the optical axis, mm.
    source_radius_mm : array_like
        1/e radius ω0 of the emitting area, mm.
    divergence_deg : array_like
        1/e half-angle θ of the emitted beam, degrees.
    mirror_radius_mm : array_like, optional
        Radius of curvature R of the convex mirror, mm; ``numpy.inf`` (default) is flat.

    Returns
    -------
    numpy.ndarray
        Spot radius ω at the sensor plane (1/e irradiance radius), mm.

    References
    ----------
    Osman et al. (2024), Eq 4 (ω = f(d)); A. E. Siegman, *Lasers* (1986), ch. 15, for the
    ray-transfer matrices of free space and a spherical mirror.
    """
    d = np.asarray(distance_mm, dtype=float)
    power = 2.0 / np.asarray(mirror_radius_mm, dtype=float)
    slope = np.tan(np.deg2rad(divergence_deg))
    # the compiled scalar formula's Python source, evaluated by numpy over the arrays
    return np.sqrt(kernel.round_trip_radius_sq.py_func(d, d, power, source_radius_mm, slope))


def gaussian_power(emitted_power, detector_area_mm2, beam_radius_mm, offset_mm=0.0):
    """Power collected by a small detector in a Gaussian spot (paper Eq 4 and its offset form).

    ``P = P_E · S_area / (π ω²) · exp(−r²/ω²)``; with r = 0 this is the paper's Eq 4. For an
    elliptical spot pass two radii and the offset along each: ``P = P_E · S_area /
    (π ω1 ω2) · exp(−r1²/ω1² − r2²/ω2²)``.

    Parameters
    ----------
    emitted_power : array_like
        Power P_E reaching the sensor plane, in any unit (the result has the same unit).
    detector_area_mm2 : array_like
        Detector area S_area, mm².
    beam_radius_mm : array_like or tuple of array_like
        1/e irradiance radius ω of the spot, mm, or its two principal radii (ω1, ω2).
    offset_mm : array_like or tuple of array_like, optional
        Distance r from the spot centre to the detector centre, mm, or its components
        (r1, r2) along the two principal directions.

    Returns
    -------
    numpy.ndarray
        Collected power, in the unit of ``emitted_power``.

    References
    ----------
    Osman et al. (2024), Eq 4.
    """
    radii = beam_radius_mm if isinstance(beam_radius_mm, tuple) else (beam_radius_mm,) * 2
    offsets = offset_mm if isinstance(offset_mm, tuple) else (offset_mm, 0.0)
    exponent = sum(np.square(r / w) for r, w in zip(offsets, radii, strict=True))
    return emitted_power * detector_area_mm2 / (np.pi * radii[0] * radii[1]) * np.exp(-exponent)


def spot_displacement(axial_distance_mm, normal_a, normal_u, normal_w):
    """Displacement Δ of the reflected spot centre in the sensor plane, in the sensor frame.

    The optical axis a meets the reflector after a distance t, where the outward normal is
    n = (n_a, n_u, n_w) in the sensor frame (a, u, w) and the incidence i has cos i = −n_a.
    The reflected ray ``r = a − 2 (a·n) n`` returns to the sensor plane at
    ``Δ = 2 t cos i · (n_u, n_w) / cos 2i``: zero at normal incidence and about
    ``2 t tan i`` for a small tilt.

    Parameters
    ----------
    axial_distance_mm : array_like
        Distance t along the axis to the reflector, mm.
    normal_a, normal_u, normal_w : array_like
        Components of the outward unit normal at the hit (n_a < 0 when the axis meets the
        front of the sphere).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Δ along u and along w, mm. NaN where the reflected ray does not come back to the
        sensor plane (incidence of 45° or more).
    """
    cos_i = -np.asarray(normal_a, dtype=float)
    cos_2i = 2.0 * cos_i * cos_i - 1.0
    scale = 2.0 * np.asarray(axial_distance_mm) * cos_i / np.where(cos_2i > 0.0, cos_2i, np.nan)
    return scale * normal_u, scale * normal_w


def coupling(
    axial_distance_mm,
    normal_a,
    normal_u,
    normal_w,
    detector_offset_mm,
    *,
    source_radius_mm,
    divergence_deg,
    detector_area_mm2,
    reflectance=1.0,
    mirror_radius_mm=np.inf,
):
    """Fraction of the emitted power that reaches the detector (dimensionless).

    Paper Eq 4 per unit emitted power, extended to a convex mirror met at incidence i (see
    the module notes and docs/model.md):
    ``η = ρ · S_area · K / (π ω_t ω_s) · exp(−(m_t cos 2i)²/ω_t² − m_s²/ω_s²)``, with
    m = Δ − e split into its parts m_t in the plane of incidence and m_s across it, Δ from
    :func:`spot_displacement`, e the detector offset along the sensor frame's u, ω_t and
    ω_s the returning beam's tangential and sagittal 1/e radii at the detector, and
    K = cos 2i (1 + m_t sin 2i / ℓ_t) the obliquity of the sensor plane to the beam there.
    At normal incidence K = 1 and ω_t = ω_s = :func:`beam_radius`. The formula is
    :func:`reflector_opt.model.kernel.coupling_and_spot`, applied elementwise with broadcasting.

    Parameters
    ----------
    axial_distance_mm : array_like, shape P + S
        Emitter-to-reflector distance t along the optical axis, mm.
    normal_a, normal_u, normal_w : array_like, shape P + S
        Outward unit normal at the axis hit, in the sensor frame (a, u, w).
    detector_offset_mm : array_like, shape S
        Distance ‖e‖ from the emitter to the detector centre along u, mm.
    source_radius_mm, divergence_deg : array_like, shape S
        Emitter 1/e radius ω0 (mm) and 1/e half-angle θ (degrees).
    detector_area_mm2 : array_like, shape S
        Detector area S_area, mm².
    reflectance : float, optional
        Reflectance ρ of the reflector surface (0–1).
    mirror_radius_mm : float, optional
        Reflector radius of curvature R, mm (``numpy.inf`` for a flat mirror).

    Returns
    -------
    numpy.ndarray
        Shape ``P + S``; detected over emitted power. 0 where the axis misses the reflector
        or the reflected beam does not return (incidence ≥ 45°).

    References
    ----------
    Osman et al. (2024), Eq 4; docs/model.md for the extension.
    """
    # the compiled formula may evaluate both sides of its branches (e.g. 1/sin i at normal
    # incidence) and keep the right one; the floating-point flags this raises mean nothing
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return kernel.coupling_ufunc(
            axial_distance_mm,
            normal_a,
            normal_u,
            normal_w,
            detector_offset_mm,
            source_radius_mm,
            np.tan(np.deg2rad(divergence_deg)),
            detector_area_mm2,
            reflectance,
            2.0 / np.asarray(mirror_radius_mm, dtype=float),
        )
