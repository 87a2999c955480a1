"""Slow, independent references for the closed-form model, used to test it (never in a loop).

* :func:`direct_response` is the straightforward formulation of the same closed-form model:
  a 3×3 rotation matrix per pose (Eq 1), vectors in the unit frame, the reflected axis ray
  and its crossing of the sensor plane found explicitly, and the beam radius from an explicit
  product of ray-transfer matrices. It is the baseline of the forward-model benchmark.
* :func:`raytrace_coupling` drops the closed form's approximations: it traces rays from a
  Gaussian emitter (finite size, Gaussian slopes), reflects each off the exact sphere and
  counts those landing on the detector's actual disc.
"""

from __future__ import annotations

import numpy as np

from reflector_opt.model.geometry import rotation_x, rotation_y, trace_axis, unit
from reflector_opt.model.optics import coupling

__all__ = ["closed_form_coupling", "direct_response", "raytrace_coupling"]


def _dot(u, v):
    return np.sum(u * v, axis=-1)


def _round_trip_matrix(outward_mm, return_mm, mirror_power):
    """Ray-transfer matrix: free space out, a mirror of focal power P (1/mm), free space back."""
    shape = np.shape(outward_mm)

    def matrix(a, b, c, d):
        return np.stack([np.stack([a, b], -1), np.stack([c, d], -1)], -2)

    one, zero = np.ones(shape), np.zeros(shape)
    out = matrix(one, np.asarray(outward_mm, dtype=float), zero, one)
    mirror = matrix(one, zero, np.broadcast_to(mirror_power, shape), one)
    back = matrix(one, np.asarray(return_mm, dtype=float), zero, one)
    return back @ mirror @ out


def _spot_radius(matrix, model):
    slope = np.tan(np.deg2rad(model.divergence_deg))
    return np.hypot(matrix[..., 0, 0] * model.source_radius_mm, matrix[..., 0, 1] * slope)


def direct_response(design, pitch_deg, roll_deg):
    """Distances, couplings and voltages by the direct vector formulation.

    The reflected axis ray is found explicitly in the unit frame, the return length and the
    spot's tangential and sagittal radii from explicit ray-transfer matrix products.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    pitch_deg, roll_deg : array_like
        Pose angles in degrees, broadcast to shape P.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, numpy.ndarray)
        Eq 3 distance (mm), coupling and volts, each of shape ``P + (n_sensors,)``; they must
        equal those of :func:`reflector_opt.model.forward.respond`.
    """
    pitch, roll = np.broadcast_arrays(
        np.asarray(pitch_deg, dtype=float), np.asarray(roll_deg, dtype=float)
    )
    rotation = rotation_x(roll) @ rotation_y(pitch)
    s1 = rotation @ np.asarray(design.reflector.centre_mm, dtype=float)
    r_s = design.reflector.radius_mm
    distance, coupling, volts = [], [], []
    for placement, model in zip(design.sensors, design.models, strict=True):
        f = np.asarray(placement.position_mm, dtype=float)
        a = unit(placement.axis)
        p = f - s1
        distance.append(np.linalg.norm(p, axis=-1) - r_s)
        b = _dot(p, a)
        disc = b * b - (_dot(p, p) - r_s * r_s)
        t = -b - np.sqrt(np.where(disc >= 0.0, disc, np.nan))
        q = f + t[..., None] * a
        n = (q - s1) / r_s
        cos_i = -_dot(a, n)
        reflected = a - 2.0 * _dot(a, n)[..., None] * n
        cos_2i = -_dot(reflected, a)
        detector = f + model.emitter_detector_mm * placement.in_plane_detector_direction
        # the detector's distance down the returning beam and its offset from the beam axis
        down_beam = np.where(cos_2i > 0.0, _dot(detector - q, reflected), np.nan)
        across = detector - q - down_beam[..., None] * reflected
        in_plane = n + cos_i[..., None] * a
        sin_i = np.linalg.norm(in_plane, axis=-1)
        sagittal = np.cross(a, in_plane / np.where(sin_i > 0.0, sin_i, 1.0)[..., None])
        across_s = _dot(across, sagittal)
        across_t_sq = _dot(across, across) - across_s**2
        power_t, power_s = 2.0 / (r_s * cos_i), 2.0 * cos_i / r_s
        w_t = _spot_radius(_round_trip_matrix(t, down_beam, power_t), model)
        w_s = _spot_radius(_round_trip_matrix(t, down_beam, power_s), model)
        # obliquity cos ψ · sec φ of the ray from the tangential virtual source to the detector
        virtual_source = q - (t / (1.0 + t * power_t))[..., None] * reflected
        ray = detector - virtual_source
        length_along = _dot(ray, reflected)
        obliquity = -_dot(ray, a) / length_along
        eta = (
            design.reflector.reflectance
            * model.detector_area_mm2
            * obliquity
            / (np.pi * w_t * w_s)
            * np.exp(-across_t_sq / w_t**2 - across_s**2 / w_s**2)
        )
        eta = np.where(np.isnan(eta), 0.0, eta)
        coupling.append(eta)
        volts.append(model.output_voltage(eta))
    return tuple(np.stack(x, axis=-1) for x in (distance, coupling, volts))


def raytrace_coupling(
    sensor_mm,
    axis,
    detector_offset_mm,
    sphere_centre_mm,
    radius_mm,
    model,
    *,
    reflectance=1.0,
    n_rays=2_000_000,
    seed=0,
):
    """Monte Carlo ray trace of the emitter's beam off the exact sphere onto the detector.

    Rays start at points drawn from a Gaussian source of 1/e radius ω0 in the sensor plane,
    with Gaussian slopes of 1/e width tan θ about the axis (the assumptions of the closed
    form). Each is intersected with the exact sphere, reflected (r = d − 2 (d·n) n) and
    followed back to the sensor plane; the detector is a disc of area S_area centred at f + e.

    Parameters
    ----------
    sensor_mm : array_like, shape (3,)
        Emitter position f, mm.
    axis : array_like, shape (3,)
        Optical axis a towards the reflector.
    detector_offset_mm : array_like, shape (3,)
        Vector e from the emitter to the detector centre, perpendicular to a, mm.
    sphere_centre_mm : array_like, shape (3,)
        Sphere centre at the pose of interest (already rotated), mm.
    radius_mm : float
        Sphere radius, mm.
    model : reflector_opt.model.sensors.SensorModel
        Supplies ω0, θ and S_area.
    reflectance : float, optional
        Reflectance ρ.
    n_rays : int, optional
        Rays traced (in chunks of 500,000).
    seed : int, optional
        Seed of the random generator.

    Returns
    -------
    (float, float)
        Detected over emitted power and its Monte Carlo standard error.
    """
    rng = np.random.default_rng(seed)
    f = np.asarray(sensor_mm, dtype=float)
    a = unit(axis)
    helper = np.eye(3)[np.argmin(np.abs(a))]
    u = unit(helper - (helper @ a) * a)
    w = np.cross(a, u)
    detector = f + np.asarray(detector_offset_mm, dtype=float)
    detector_radius = np.sqrt(model.detector_area_mm2 / np.pi)
    source_sigma = model.source_radius_mm / np.sqrt(2.0)
    slope_sigma = np.tan(np.deg2rad(model.divergence_deg)) / np.sqrt(2.0)
    centre = np.asarray(sphere_centre_mm, dtype=float)
    hits = 0
    remaining = int(n_rays)
    while remaining > 0:
        n = min(remaining, 500_000)
        remaining -= n
        g = rng.standard_normal((4, n))
        origin = f + (source_sigma * g[0])[:, None] * u + (source_sigma * g[1])[:, None] * w
        direction = unit(a + (slope_sigma * g[2])[:, None] * u + (slope_sigma * g[3])[:, None] * w)
        p = origin - centre
        b = _dot(p, direction)
        c = _dot(p, p) - radius_mm**2
        disc = b * b - c
        ok = (disc > 0.0) & (b < 0.0)
        # t = −b − sqrt(b² − c), written as c / (−b + sqrt(b² − c)) to stay exact for huge R
        t = c[ok] / (-b[ok] + np.sqrt(disc[ok]))
        d = direction[ok]
        q = origin[ok] + t[:, None] * d
        normal = (q - centre) / radius_mm
        r = d - 2.0 * _dot(d, normal)[:, None] * normal
        r_dot_a = r @ a
        back = r_dot_a < 0.0
        along = -((q[back] - f) @ a) / r_dot_a[back]
        landing = q[back] + along[:, None] * r[back]
        hits += int(
            np.count_nonzero(_dot(landing - detector, landing - detector) <= detector_radius**2)
        )
    fraction = hits / n_rays
    return reflectance * fraction, reflectance * np.sqrt(fraction * (1.0 - fraction) / n_rays)


def closed_form_coupling(
    sensor_mm, axis, detector_offset_mm, sphere_centre_mm, radius_mm, model, *, reflectance=1.0
):
    """The closed-form coupling for the arguments of :func:`raytrace_coupling`.

    Parameters
    ----------
    sensor_mm, axis, detector_offset_mm, sphere_centre_mm, radius_mm, model, reflectance
        As for :func:`raytrace_coupling` (the sphere already at the pose of interest).

    Returns
    -------
    float
        Detected over emitted power from :func:`reflector_opt.model.optics.coupling`.
    """
    hit = trace_axis(
        sensor_mm,
        axis,
        sphere_centre_mm,
        radius_mm,
        0.0,
        0.0,
        detector_direction=detector_offset_mm,
    )
    return float(
        coupling(
            hit.axial_distance_mm,
            hit.normal_a,
            hit.normal_u,
            hit.normal_w,
            np.linalg.norm(detector_offset_mm),
            source_radius_mm=model.source_radius_mm,
            divergence_deg=model.divergence_deg,
            detector_area_mm2=model.detector_area_mm2,
            reflectance=reflectance,
            mirror_radius_mm=radius_mm,
        )
    )
