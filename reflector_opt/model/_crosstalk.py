"""Optical crosstalk between the sensors of a unit: one sensor's LED seen by another's detector.

The forward model (:mod:`.forward`, :mod:`.optics`) gives each sensor's own coupling, its LED
to its own detector. Light from sensor j's LED also reaches sensor k's detector by the
reflector, in the two shares of the surface model (:mod:`.surface`, docs/model.md, "Surface
model"): ``η_kj = ρ · [f · η_mirror,kj + (1 − f) · η_Lambert,kj]``. This module computes η_kj
for every ordered pair j ≠ k, vectorised over poses (a loop over the pairs only), with a point
emitter at f_j and a point detector at ``y_k = f_k + e_k`` (e_k in k's plane), in the frames
and the Eq 1 sphere centre the rest of the model uses (:mod:`.geometry`):

* **Which poses can pass light.** A reflected path from j to k needs a point of the sphere
  seen from both. Each sees the cap of half-angle ``arccos(R / |x − c|)`` about the direction
  from the centre c to it, so where the angle between ``f_j − c`` and ``y_k − c`` exceeds the
  sum of the two half-angles no point is shared and both shares are zero, exactly (a mirror
  path needs its specular point in both caps; a diffuse path needs a lit point k sees). The
  default design's sensors, 90° apart, are such a pair at every pose.
* **Mirror share** — the ray tube at the exact specular point P of the sphere for f_j and
  y_k (geometrical optics; the exact reference's formula, :mod:`.exact`):
  ``η_mirror = S_k · I_j(v) · cos ψ_k / (B_t · B_s)``, ``B_t = s1 + s2 + 2 s1 s2/(R cos i)``,
  ``B_s = s1 + s2 + 2 s1 s2 cos i/R``, ``s1 = |P − f_j|``, ``s2 = |y_k − P|``, v the ray leaving
  f_j, ψ_k the returning ray's angle to k's own normal −a_k; zero where P is hidden from
  either end (the segment between them crosses the sphere). The emitter's intensity is
  ``I_j = q(s)/cos³γ`` (s the ray's slope about a_j, γ its angle to a_j) with the Gaussian
  slope density widened, along the slope, by the size of the emitter and of the detector:
  ``q(s) = exp(−|s|²/T_r²) / (π T T_r)``,
  ``T_r² = T² + (1 + |s|²) · [ω0² A_t² + (1 + |s|²) (r_d²/2) cos²ψ_k] / B_t²``,
  ``A_t = 1 + 2 s2/(R cos i)``, T = tan θ_j, ω0 the emitter's 1/e radius, r_d the radius of
  k's detector disc (S_k = π r_d²). Derivation: by the ray-transfer matrices of the unfolded
  path in the plane of incidence (free space s1, a convex mirror of power 2/(R cos i), free
  space s2: ``[[A_t, B_t], [·, ·]]``; Siegman, *Lasers*, 1986, ch. 15; Hecht, *Optics*, 5th
  ed., §6.2) a source point moved by δ across the ray must leave at an angle changed by
  ``−A_t δ/B_t`` to reach the same detector point, and a detector point moved by δ changes
  it by ``δ/B_t``; the sensor planes foreshorten δ by cos γ and cos ψ_k, an angle change
  dφ is a slope change ``(1 + |s|²) dφ``, and Gaussian widths add in quadrature (the
  source's 1/e radius ω0; r_d/√2 for the disc, the same variance). At ``|s| ≪ T`` the widening
  is nothing; on the beam's flank, where the cross path leaves, the point emitter alone
  under-counts (the mean of a Gaussian's tail over a finite source exceeds its value at the
  centre): by 1–17 % where the crosstalk fraction is above 1e-3, by up to 60 % further out.
* **Lambertian share** — the lit spot as a set of rays: a Gauss–Hermite rule of
  :data:`SLOPE_NODES` × :data:`SLOPE_NODES` slopes about a_j, of 1/e width ``ω(d)/d`` with
  ``ω(d) = sqrt(ω0² + d² T²)`` the spot radius at the Eq 3 distance d
  (:func:`~reflector_opt.model._optics.beam_radius`), so that the point emitter lights the
  spot the extended one does. A ray of power w meeting the sphere at P (normal n) makes,
  by Lambert's law, the radiant intensity ``w cos β'/π`` towards y_k:
  ``η_Lambert = S_k Σ w · cos β' cos ψ_k / (π |y_k − P|²)``, β' the angle between n and
  ``y_k − P``.

Agreement with :func:`~reflector_opt.model._exact.exact_design_cross_coupling` (docs/model.md,
"Crosstalk between the sensors of a unit"; ``python benchmarks/crosstalk_agreement.py``), on
the default unit with its sensors 15°–40° apart and with three sensors 20° apart, 25 poses
over ±15°: the mirror share within 1.5 % wherever the cross coupling is at least 1e-4 of the
own coupling; the Lambertian share within 3 % where it is at least 1e-2 of it, 7.3 % from
1e-3 and 38 % from 1e-4 (the rays' rule thins out in the beam's flank); no error larger than
1.3e-3 of the own coupling, and under 1e-4 of it where the crosstalk is below 1e-3.

Left out: light that reaches the other detector not by the reflector — through the flexible
PCB, the printed body or the sensor's package, or straight across (the Gaussian pattern puts
nothing there; a real package leaks) — which is a conditions input, not geometry; shadowing
of the sphere by the packages; the measured-curve correction of the own coupling (a measured
flat-target curve says nothing about the cross path).
"""

import itertools
from typing import NamedTuple

import numpy as np

from reflector_opt.model._exact import gauss_hermite_2d, specular_points
from reflector_opt.model._forward import respond
from reflector_opt.model._geometry import rotate_centre, sensor_distance, sensor_frames, unit
from reflector_opt.model._optics import beam_radius
from reflector_opt.model._surface import SurfaceCoupling
from reflector_opt.util._errors import InputError

#: Gauss–Hermite nodes per slope axis of the Lambertian share's rays (64 rays per pair and
#: pose; with 6 per axis the worst errors of the agreement benchmark grow from 3 % to 7 %
#: where the crosstalk fraction is above 1e-2, and from 7 % to 23 % between 1e-3 and 1e-2).
SLOPE_NODES = 8
#: Bisection steps of the specular point: the angle to 2⁻²⁴ of the arc (the exact
#: reference's 64 reach round-off; 24 change the coupling by less than 1e-6).
SPECULAR_STEPS = 24


class _Emitter(NamedTuple):
    """Sensor j's emitter: centre f_j (mm), frame rows a, u, w, T = tan θ, ω0 (mm), θ (deg)."""

    position: np.ndarray
    frame: np.ndarray
    slope: float
    source_radius: float
    divergence_deg: float


class _Detector(NamedTuple):
    """Sensor k's detector: centre y_k (mm), axis a_k, area S_k (mm²)."""

    point: np.ndarray
    axis: np.ndarray
    area: float


def cross_surface_couplings(design, pitch_deg, roll_deg):
    """Mirror and Lambertian couplings from every sensor's LED to every other's detector.

    See the module notes for the equations. Sensor pairs whose views of the sphere share no
    point at a pose are zero there without computation.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    pitch_deg, roll_deg : array_like
        Pitch γ and roll α, degrees; broadcast together to shape P.

    Returns
    -------
    SurfaceCoupling
        Arrays of shape ``P + (n_sensors, n_sensors)`` for a surface of reflectance 1:
        entry ``[..., k, j]`` from emitter j to detector k, detected over emitted power;
        the diagonal is zero (the forward model holds the own coupling). Raises
        :class:`~reflector_opt.util._errors.CollisionError` if a sensor lies inside the
        sphere at a pose, :class:`~reflector_opt.util._errors.InputError` for a pose that is
        not finite.
    """
    pitch, roll = _poses(pitch_deg, roll_deg)
    reflector = design.reflector
    radius = float(reflector.radius_mm)
    distance = sensor_distance(design.positions_mm, reflector.centre_mm, radius, pitch, roll)
    centres = rotate_centre(reflector.centre_mm, pitch, roll)
    emitters, detectors = _parts(design)
    n = len(emitters)
    mirror = np.zeros((*pitch.shape, n, n))
    lambertian = np.zeros_like(mirror)
    for k, j in itertools.permutations(range(n), 2):
        shared = _shared_view(emitters[j].position, detectors[k].point, centres, radius)
        at = centres[shared]
        mirror[..., k, j][shared] = _mirror_share(emitters[j], detectors[k], at, radius)
        lambertian[..., k, j][shared] = _lambertian_share(
            emitters[j], detectors[k], at, radius, distance[..., j][shared]
        )
    return SurfaceCoupling(mirror=mirror, lambertian=lambertian)


def cross_couplings(design, pitch_deg, roll_deg):
    """Coupling from every sensor's LED to every other sensor's detector, with the surface.

    ``η_kj = ρ · [f · η_mirror,kj + (1 − f) · η_Lambert,kj]`` with the reflectance ρ and the
    specular fraction f of ``design.reflector``, as the forward model applies them to the
    own coupling; the shares are :func:`cross_surface_couplings`'.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    pitch_deg, roll_deg : array_like
        Pitch γ and roll α, degrees; broadcast together to shape P.

    Returns
    -------
    numpy.ndarray
        Shape ``P + (n_sensors, n_sensors)``: entry ``[..., k, j]`` is the power on sensor
        k's detector over the power sensor j's LED emits (dimensionless); the diagonal is
        zero.
    """
    parts = cross_surface_couplings(design, pitch_deg, roll_deg)
    return parts.total(design.reflector.reflectance, design.reflector.specular_fraction)


def crosstalk_fraction(design, pitch_deg, roll_deg):
    """Cross coupling over own coupling: how much of its neighbour's light a detector gets.

    ``χ_kj = η_kj / η_kk``, η_kj from :func:`cross_couplings` and η_kk the forward model's
    own coupling (:func:`reflector_opt.model._forward.respond`). With every LED driven
    alike, sensor k's detector receives ``η_kk · (1 + Σ_j χ_kj)`` of one LED's power.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    pitch_deg, roll_deg : array_like
        Pitch γ and roll α, degrees; broadcast together to shape P.

    Returns
    -------
    numpy.ndarray
        Shape ``P + (n_sensors, n_sensors)``, dimensionless: entry ``[..., k, j]`` for
        emitter j and detector k; the diagonal is zero; NaN where the own coupling is zero.
    """
    cross = cross_couplings(design, pitch_deg, roll_deg)
    own = respond(design, pitch_deg, roll_deg).coupling[..., :, None]
    own = np.broadcast_to(own, cross.shape)
    return np.divide(cross, own, out=np.full(cross.shape, np.nan), where=own > 0.0)


def _poses(pitch_deg, roll_deg):
    """Pitch and roll broadcast together, as floats; InputError naming one that is not finite."""
    pitch, roll = np.broadcast_arrays(
        np.asarray(pitch_deg, dtype=float), np.asarray(roll_deg, dtype=float)
    )
    for name, values in (("pitch_deg", pitch), ("roll_deg", roll)):
        if not np.isfinite(values).all():
            raise InputError(f"{name}: poses must be finite angles in degrees")
    return pitch, roll


def _parts(design):
    """Each sensor's emitter and detector, in the frames of :func:`.geometry.sensor_frames`."""
    frames = sensor_frames(design.axes, [s.detector_direction for s in design.sensors])
    points = design.positions_mm + design.detector_offsets_mm
    emitters, detectors = [], []
    for position, frame, point, model in zip(
        design.positions_mm, frames, points, design.models, strict=True
    ):
        slope = float(np.tan(np.deg2rad(model.divergence_deg)))
        emitters.append(
            _Emitter(position, frame, slope, model.source_radius_mm, model.divergence_deg)
        )
        detectors.append(_Detector(point, frame[0], model.detector_area_mm2))
    return emitters, detectors


def _shared_view(source_mm, target_mm, centres_mm, radius_mm):
    """True where some point of the sphere is seen from both points (their caps overlap)."""
    p, q = source_mm - centres_mm, target_mm - centres_mm
    p_len, q_len = np.linalg.norm(p, axis=-1), np.linalg.norm(q, axis=-1)
    between = np.arccos(np.clip(np.sum(p * q, -1) / (p_len * q_len), -1.0, 1.0))
    caps = np.arccos(np.minimum(radius_mm / p_len, 1.0)) + np.arccos(
        np.minimum(radius_mm / q_len, 1.0)
    )
    return between < caps


def _mirror_share(emitter, detector, centres_mm, radius_mm):
    """η_mirror of the module notes at sphere centres (N, 3): the widened ray tube."""
    x = np.broadcast_to(emitter.position, centres_mm.shape)
    y = np.broadcast_to(detector.point, centres_mm.shape)
    point, normal = specular_points(x, y, centres_mm, radius_mm, iterations=SPECULAR_STEPS)
    to_source, to_detector = x - point, y - point
    s1 = np.linalg.norm(to_source, axis=-1)
    s2 = np.linalg.norm(to_detector, axis=-1)
    cos_i = np.sum(normal * to_source, -1) / s1
    cos_psi = -(to_detector @ detector.axis) / s2
    cos_g = -(to_source @ emitter.frame[0]) / s1
    seen = np.sum(normal * to_detector, -1) > 0.0  # no specular point: the segment crosses
    lit = (cos_i > 0.0) & (cos_psi > 0.0) & (cos_g > 0.0) & seen
    cos_i, cos_g = np.where(lit, cos_i, 1.0), np.where(lit, cos_g, 1.0)
    bend = 2.0 * s1 * s2 / radius_mm
    tangential, sagittal = s1 + s2 + bend / cos_i, s1 + s2 + bend * cos_i
    magnification = 1.0 + 2.0 * s2 / (radius_mm * cos_i)
    along = 1.0 / cos_g**2  # 1 + |s|²
    spread_sq = emitter.source_radius**2 * magnification**2 + along * (
        0.5 * detector.area / np.pi * cos_psi**2
    )
    width_sq = emitter.slope**2 + along * spread_sq / tangential**2
    q = np.exp(-(along - 1.0) / width_sq) / (np.pi * emitter.slope * np.sqrt(width_sq))
    coupling = detector.area * q / cos_g**3 * cos_psi / (tangential * sagittal)
    return np.where(lit, coupling, 0.0)


def _lambertian_share(emitter, detector, centres_mm, radius_mm, distance_mm):
    """η_Lambert of the module notes at sphere centres (N, 3): rays of the lit spot."""
    a, u, w = emitter.frame
    width = beam_radius(distance_mm, emitter.source_radius, emitter.divergence_deg) / distance_mm
    p = emitter.position - centres_mm
    beyond = np.sum(p * p, -1) - radius_mm**2
    total = np.zeros(len(centres_mm))
    for (z_u, z_w), weight in zip(*gauss_hermite_2d(SLOPE_NODES, 1.0), strict=True):
        v = unit(a + (width * z_u)[:, None] * u + (width * z_w)[:, None] * w)
        b = np.sum(p * v, -1)
        disc = b * b - beyond
        hit = (disc >= 0.0) & (b < 0.0)
        point = emitter.position + (-b - np.sqrt(np.maximum(disc, 0.0)))[:, None] * v
        to_detector = detector.point - point
        r = np.linalg.norm(to_detector, axis=-1)
        cos_out = np.sum((point - centres_mm) * to_detector, -1) / (radius_mm * r)
        cos_psi = -(to_detector @ detector.axis) / r
        seen = hit & (cos_out > 0.0) & (cos_psi > 0.0)
        total += weight * np.where(seen, cos_out * cos_psi / r**2, 0.0)
    return detector.area * total / np.pi
