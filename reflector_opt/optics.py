"""Reflected optical power: paper Eq 4 and its extension to a convex, tilted reflector.

Beam-radius convention: every beam radius ω here is the **1/e irradiance radius** of a
Gaussian spot, ``I(r) = P / (π ω²) · exp(−r²/ω²)``. With this convention the paper's Eq 4,
``P = P_E · S_area / (π ω²)``, is exactly the power on a small detector of area S_area at the
spot centre, and the power at a distance r from the centre carries the factor exp(−r²/ω²).

The model (see docs/model.md):

* the emitter is a Gaussian source of 1/e radius ω0 whose rays have Gaussian slopes of 1/e
  width tan θ; a round trip over a distance d to a convex mirror of radius R and back has the
  ray-transfer matrix ``[[1, d], [0, 1]] · [[1, 0], [2/R, 1]] · [[1, d], [0, 1]]
  = [[1 + 2d/R, 2d(1 + d/R)], [2/R, 1 + 2d/R]]``, so the returning spot has
  ``ω² = ((1 + 2d/R) ω0)² + (2 d tan θ (1 + d/R))²`` (Gaussian widths add in quadrature);
  a flat mirror is the limit R → ∞;
* the detector centre sits at an offset e from the emitter in the sensor plane, and a tilted
  reflector moves the spot centre by Δ (the reflected optical axis meets the sensor plane
  there), so the detected fraction is ``ρ · S_area / (π ω²) · exp(−|Δ − e|²/ω²)``.

For a flat mirror at normal incidence (Δ = 0) the response rises and then falls with d,
peaking where ω(d) = |e|: the familiar reflective-sensor curve.
"""

from __future__ import annotations

import numpy as np

__all__ = ["beam_radius", "coupling", "gaussian_power", "spot_displacement"]


def beam_radius(distance_mm, source_radius_mm, divergence_deg, mirror_radius_mm=np.inf):
    """1/e radius of the returning spot after a round trip to a convex mirror.

    ``ω(d) = sqrt(((1 + 2d/R) ω0)² + (2 d tan θ (1 + d/R))²)``, from the round-trip
    ray-transfer matrix ``[[1 + 2d/R, 2d(1 + d/R)], [2/R, 1 + 2d/R]]`` applied to a Gaussian
    source of radius ω0 and Gaussian slope spread tan θ. For a flat mirror (R = ∞) this is
    ``sqrt(ω0² + (2 d tan θ)²)``, the beam ω = f(d) that the paper's Eq 4 leaves open.

    Parameters
    ----------
    distance_mm : array_like
        One-way distance d from the emitter to the mirror along the optical axis, mm.
    source_radius_mm : float
        1/e radius ω0 of the emitting area, mm.
    divergence_deg : float
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
    curvature = 1.0 / np.asarray(mirror_radius_mm, dtype=float)
    source = (1.0 + 2.0 * d * curvature) * source_radius_mm
    spread = 2.0 * d * np.tan(np.deg2rad(divergence_deg)) * (1.0 + d * curvature)
    return np.sqrt(source * source + spread * spread)


def gaussian_power(emitted_power, detector_area_mm2, beam_radius_mm, offset_mm=0.0):
    """Power collected by a small detector in a Gaussian spot (paper Eq 4 and its offset form).

    ``P = P_E · S_area / (π ω²) · exp(−r²/ω²)``; with r = 0 this is the paper's Eq 4.

    Parameters
    ----------
    emitted_power : array_like
        Power P_E reaching the sensor plane, in any unit (the result has the same unit).
    detector_area_mm2 : float
        Detector area S_area, mm².
    beam_radius_mm : array_like
        1/e irradiance radius ω of the spot, mm.
    offset_mm : array_like, optional
        Distance r from the spot centre to the detector centre, mm.

    Returns
    -------
    numpy.ndarray
        Collected power, in the unit of ``emitted_power``.

    References
    ----------
    Osman et al. (2024), Eq 4.
    """
    w2 = np.square(beam_radius_mm)
    r2 = np.square(offset_mm)
    return emitted_power * detector_area_mm2 / (np.pi * w2) * np.exp(-r2 / w2)


def spot_displacement(sensor_mm, axis, hit_point_mm, normal):
    """Displacement Δ of the reflected spot centre in the sensor plane.

    The optical axis a meets the reflector at q with outward normal n; the reflected ray
    ``r = a − 2 (a·n) n`` leaves q and meets the sensor plane (through f, normal a) at
    ``q + u r`` with ``u = −((q − f)·a)/(r·a)``. Δ is that point minus f: zero at normal
    incidence, about ``2 t tan(incidence)`` for a tilt.

    Parameters
    ----------
    sensor_mm : array_like, shape S + (3,)
        Sensor (emitter) positions f, mm.
    axis : array_like, shape S + (3,)
        Unit optical axes a, pointing towards the reflector.
    hit_point_mm : array_like, shape P + S + (3,)
        Axis–sphere intersection q, mm (see :func:`reflector_opt.geometry.axial_distance`).
    normal : array_like, shape P + S + (3,)
        Outward unit normal n at q.

    Returns
    -------
    numpy.ndarray
        Shape ``P + S + (3,)``: Δ in mm, a vector in the sensor plane. NaN where the hit is NaN
        or the reflected ray runs parallel to the sensor plane.
    """
    f = np.asarray(sensor_mm, dtype=float)
    a = np.asarray(axis, dtype=float)
    q = np.asarray(hit_point_mm, dtype=float)
    n = np.asarray(normal, dtype=float)
    a_dot_n = np.einsum("...i,...i->...", a, n)
    r = a - 2.0 * a_dot_n[..., None] * n
    r_dot_a = np.einsum("...i,...i->...", r, a)
    along = np.einsum("...i,...i->...", q - f, a)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.where(r_dot_a < 0.0, -along / r_dot_a, np.nan)
    return q + u[..., None] * r - f


def coupling(
    distance_mm,
    displacement_mm,
    detector_offset_mm,
    *,
    source_radius_mm,
    divergence_deg,
    detector_area_mm2,
    reflectance=1.0,
    mirror_radius_mm=np.inf,
):
    """Fraction of the emitted power that reaches the detector (dimensionless).

    ``η = ρ · S_area / (π ω²) · exp(−|Δ − e|²/ω²)`` with ω from :func:`beam_radius`: paper
    Eq 4 per unit emitted power, extended by the emitter–detector offset e and the tilt-induced
    spot displacement Δ.

    Parameters
    ----------
    distance_mm : array_like, shape P + S
        Emitter-to-reflector distance along the optical axis, mm. NaN (axis misses) gives 0.
    displacement_mm : array_like, shape P + S + (3,)
        Spot-centre displacement Δ in the sensor plane, mm.
    detector_offset_mm : array_like, shape S + (3,)
        Vector e from the emitter to the detector centre, in the sensor plane, mm.
    source_radius_mm, divergence_deg : float
        Emitter 1/e radius ω0 (mm) and 1/e half-angle θ (degrees).
    detector_area_mm2 : float
        Detector area S_area, mm².
    reflectance : float, optional
        Reflectance ρ of the reflector surface (0–1).
    mirror_radius_mm : float, optional
        Reflector radius of curvature R, mm (``numpy.inf`` for a flat mirror).

    Returns
    -------
    numpy.ndarray
        Shape ``P + S``; detected power over emitted power.

    References
    ----------
    Osman et al. (2024), Eq 4; docs/model.md for the extension.
    """
    w = beam_radius(distance_mm, source_radius_mm, divergence_deg, mirror_radius_mm)
    miss = np.asarray(displacement_mm, dtype=float) - np.asarray(detector_offset_mm, dtype=float)
    r2 = np.einsum("...i,...i->...", miss, miss)
    eta = gaussian_power(reflectance, detector_area_mm2, w, np.sqrt(r2))
    return np.where(np.isfinite(eta), eta, 0.0)
