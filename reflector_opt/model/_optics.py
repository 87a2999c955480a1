"""Reflected optical power: paper Eq 4 extended to a convex reflector with a real surface.

The paper's Eq 4, ``P = P_E · S_area / (π ω²)`` with ω = f(d), is the power on a small
detector at the centre of a Gaussian spot. This tool computes the same quantity — detected
over emitted power, the coupling η — from the radiometry of the actual geometry (docs/model.md,
"Optics"):

* the emitter is a Gaussian source of 1/e radius ω0 in the sensor plane whose rays have
  Gaussian slopes of 1/e width T = tan θ about the optical axis;
* the detector is a disc of area S_area centred a distance e from the emitter;
* the reflector is a sphere whose surface returns the share ρ·f of the light like a mirror
  and ρ·(1 − f) diffusely (:mod:`reflector_opt.model._surface`);
* the mirror part is found from the exact specular points and ray tubes, the Lambertian part
  by integrating over the lit cap (:mod:`reflector_opt.model._kernel`), each on small Gauss
  rules over the emitter and the detector: 2 × 2 emitter points, 4 detector points and
  16 × 16 nodes on the cap, within 0.3 % of the converged integrals of
  :mod:`reflector_opt.model._exact` over the search space.

A flat target is a sphere of radius :data:`FLAT_RADIUS_MM`, whose sag over the lit area
changes the coupling by less than 1e-4. Its coupling (:func:`flat_target_coupling`) is
computed on finer rules, :data:`FLAT_TARGET_ORDERS`: near a flat target the lit patch is
wide compared with the distance and the source no longer small, so the small rules are off
by up to 8 % (Lambertian part, 0.3 mm), while fitting a measured curve needs its shape to
about 0.1 %; the finer rules are within 0.15 % of :mod:`reflector_opt.model._exact` for the
NJL5901R-2 from 0.3 mm on and 0.02 % from 0.5 mm on.
"""

import functools
import math

import numpy as np

from reflector_opt.model._surface import SurfaceCoupling

#: Radius standing in for a flat target, mm.
FLAT_RADIUS_MM = 1e5
#: Gauss rules of the compiled coupling: emitter points per axis (Gauss–Hermite), detector
#: points (one ring, Gauss–Legendre in r²), cap nodes in polar angle and in azimuth.
SOURCE_POINTS, DETECTOR_POINTS, POLAR_NODES, AZIMUTH_NODES = 2, 4, 16, 16
_ORDERS = (SOURCE_POINTS, DETECTOR_POINTS, POLAR_NODES, AZIMUTH_NODES)
#: The same four orders for a flat target (:func:`flat_target_coupling`), where the near end
#: of a measured curve needs finer rules than a convex reflector does.
FLAT_TARGET_ORDERS = (4, 8, 32, 32)


def beam_radius(distance_mm, source_radius_mm, divergence_deg):
    """1/e radius of the emitter's spot at a distance, mm (paper Eq 4's ω = f(d), one way).

    ``ω(d) = sqrt(ω0² + (d tan θ)²)``: the Gaussian source of 1/e radius ω0 widened by its
    Gaussian slopes of 1/e width tan θ (widths add in quadrature). It sizes the lit patch
    of the reflector (the printed window around it).

    Parameters
    ----------
    distance_mm : array_like
        Distance from the emitter along its axis, mm.
    source_radius_mm : array_like
        1/e radius ω0 of the emitting area, mm.
    divergence_deg : array_like
        1/e half-angle θ of the emitted beam, degrees.

    Returns
    -------
    numpy.ndarray
        1/e irradiance radius of the spot, mm.

    References
    ----------
    Osman et al. (2024), Eq 4 (ω = f(d)).
    """
    d = np.asarray(distance_mm, dtype=float)
    return np.hypot(source_radius_mm, d * np.tan(np.deg2rad(divergence_deg)))


@functools.lru_cache(maxsize=64)
def _rules(parts, orders):
    """Emitter and detector points (u, w, weight) per sensor, the polar rule and the azimuths.

    ``parts`` holds (ω0, e, S_area) per sensor and ``orders`` the rule sizes (tuples, so that
    the rules are built once).
    """
    source_points, detector_points, polar_nodes, azimuth_nodes = orders
    z, w = np.polynomial.hermite.hermgauss(source_points)
    gu, gw = np.meshgrid(z, z, indexing="ij")
    gweight = (np.outer(w, w) / np.pi).ravel()
    spokes = 2.0 * np.pi * (np.arange(detector_points) + 0.5) / detector_points
    sources, detectors = [], []
    for source_radius, offset, area in parts:
        sources.append(
            np.column_stack([source_radius * gu.ravel(), source_radius * gw.ravel(), gweight])
        )
        # one ring at the mean-square radius of the disc: exact for quadratics over it
        ring = math.sqrt(area / (2.0 * math.pi))
        detectors.append(
            np.column_stack(
                [
                    offset + ring * np.cos(spokes),
                    ring * np.sin(spokes),
                    np.full(detector_points, 1.0 / detector_points),
                ]
            )
        )
    z, w = np.polynomial.legendre.leggauss(polar_nodes)
    polar = np.column_stack([0.5 * (z + 1.0), 0.5 * w])
    angles = 2.0 * np.pi * np.arange(azimuth_nodes) / azimuth_nodes
    azimuth = np.column_stack([np.cos(angles), np.sin(angles)])
    return np.array(sources), np.array(detectors), polar, azimuth


def surface_couplings(centres_mm, radius_mm, specular_fraction, models, orders=_ORDERS):
    """Mirror and Lambertian couplings of each sensor for sphere centres in its frame.

    Parameters
    ----------
    centres_mm : array_like, shape P + (S, 3)
        Sphere centre relative to each sensor's emitter in its frame (a, u, w): along the
        optical axis a, towards the detector u, and w = a × u; mm.
    radius_mm : float
        Sphere radius R, mm.
    specular_fraction : float
        f; a part whose share is 0 is not computed (returned as 0).
    models : sequence of reflector_opt.model._sensors.SensorModel
        The S sensors' parts (ω0, θ, e, S_area).
    orders : tuple of int, optional
        Emitter points per axis, detector points, cap nodes in polar angle and in azimuth
        (default: :data:`SOURCE_POINTS`, :data:`DETECTOR_POINTS`, :data:`POLAR_NODES`,
        :data:`AZIMUTH_NODES`).

    Returns
    -------
    SurfaceCoupling
        Arrays of shape ``P + (S,)``: couplings of a surface of reflectance 1 that is all
        mirror-like and all Lambertian.
    """
    centres = np.asarray(centres_mm, dtype=float)
    shape = centres.shape[:-1]
    flat = np.ascontiguousarray(centres.reshape(-1, len(models), 3))
    optics = np.array(
        [(math.tan(math.radians(m.divergence_deg)), m.detector_area_mm2) for m in models]
    )
    out = np.empty((2, flat.shape[0], len(models)))
    parts = tuple((m.source_radius_mm, m.emitter_detector_mm, m.detector_area_mm2) for m in models)
    from reflector_opt.model import _kernel as kernel

    kernel.couplings_at(
        flat, float(radius_mm), float(specular_fraction), optics, *_rules(parts, orders), out
    )
    return SurfaceCoupling(mirror=out[0].reshape(shape), lambertian=out[1].reshape(shape))


def flat_target_coupling(distance_mm, model, reflectance=1.0, specular_fraction=1.0):
    """Coupling of one sensor facing a flat target squarely at each distance.

    ``η(d) = ρ · [f · η_mirror(d) + (1 − f) · η_Lambert(d)]`` for a flat target normal to
    the axis (the datasheet's and the lab's reference curve), on the rules
    :data:`FLAT_TARGET_ORDERS`.

    Parameters
    ----------
    distance_mm : array_like
        Emitter-to-target distance d, mm (> 0).
    model : reflector_opt.model._sensors.SensorModel
    reflectance : float, optional
        ρ of the target.
    specular_fraction : float, optional
        f of the target (1: a mirror, 0: a Lambertian white target).

    Returns
    -------
    numpy.ndarray
        η, same shape as ``distance_mm``.
    """
    d = np.asarray(distance_mm, dtype=float)
    centres = np.zeros((*d.shape, 1, 3))
    centres[..., 0, 0] = d + FLAT_RADIUS_MM
    parts = surface_couplings(
        centres, FLAT_RADIUS_MM, specular_fraction, [model], orders=FLAT_TARGET_ORDERS
    )
    return parts.total(reflectance, specular_fraction)[..., 0]
