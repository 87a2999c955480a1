"""Slow, independent references for the forward model, used to test it (never in a loop).

* :func:`direct_response` is the straightforward formulation: a 3×3 rotation matrix per pose
  (Eq 1), vectors in the unit frame, the Eq 3 distance, and the surface couplings computed at
  every pose (no interpolation over the poses). It is the baseline of the forward-model
  benchmark and checks the compiled geometry pass and the pose interpolation.
* :func:`raytrace_coupling` is a Monte Carlo ray count that shares no formula with the model:
  rays drawn from the Gaussian emitter are intersected with the exact sphere, reflected
  specularly (r = d − 2 (d·n) n) and, separately, scattered into a cosine-weighted direction
  about the normal, and counted where they land on the detector's disc.
"""

import numpy as np

from reflector_opt.model._geometry import rotation_x, rotation_y, unit, unit_perpendicular
from reflector_opt.model._operating import readings
from reflector_opt.model._optics import surface_couplings
from reflector_opt.model._surface import SurfaceCoupling


def _dot(u, v):
    return np.sum(u * v, axis=-1)


def direct_response(design, pitch_deg, roll_deg):
    """Distances, couplings and voltages by the direct vector formulation.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    pitch_deg, roll_deg : array_like
        Pose angles in degrees, broadcast to shape P.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, numpy.ndarray)
        Eq 3 distance (mm), coupling and volts, each of shape ``P + (n_sensors,)``; they
        must equal those of :func:`reflector_opt.model._forward.respond` (the couplings to
        the accuracy of its pose interpolation).
    """
    pitch, roll = np.broadcast_arrays(
        np.asarray(pitch_deg, dtype=float), np.asarray(roll_deg, dtype=float)
    )
    rotation = rotation_x(roll) @ rotation_y(pitch)
    s1 = rotation @ np.asarray(design.reflector.centre_mm, dtype=float)
    r_s = design.reflector.radius_mm
    distance, centres = [], []
    for placement in design.sensors:
        f = np.asarray(placement.position_mm, dtype=float)
        a = unit(placement.axis)
        u = placement.in_plane_detector_direction
        w = np.cross(a, u)
        p = f - s1
        distance.append(np.linalg.norm(p, axis=-1) - r_s)
        centres.append(np.stack([-_dot(p, a), -_dot(p, u), -_dot(p, w)], axis=-1))
    reflector = design.reflector
    parts = surface_couplings(
        np.stack(centres, axis=-2), r_s, reflector.specular_fraction, design.models
    )
    coupling = parts.total(reflector.reflectance, reflector.specular_fraction)
    return np.stack(distance, axis=-1), coupling, readings(coupling, design.models)


def _perpendicular_basis(normal, rng_values):
    """Cosine-weighted directions about unit normals (Malley's method)."""
    helper = np.where(np.abs(normal[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    t1 = unit(np.cross(normal, helper))
    t2 = np.cross(normal, t1)
    radius = np.sqrt(rng_values[0])
    angle = 2.0 * np.pi * rng_values[1]
    x, y = radius * np.cos(angle), radius * np.sin(angle)
    z = np.sqrt(np.maximum(1.0 - x * x - y * y, 0.0))
    return x[:, None] * t1 + y[:, None] * t2 + z[:, None] * normal


def _landing_counts(origin, direction, f, a, detector, detector_radius):
    """How many rays from origin along direction cross the sensor plane inside the disc."""
    towards = direction @ a
    back = towards < 0.0
    along = -((origin[back] - f) @ a) / towards[back]
    landing = origin[back] + along[:, None] * direction[back]
    offset = landing - detector
    return int(np.count_nonzero(_dot(offset, offset) <= detector_radius**2))


def _trace_chunk(rng, n, sensor, sphere, model):
    """Mirror and Lambertian detector hits of ``n`` rays of :func:`raytrace_coupling`.

    ``sensor`` is (f, a, u, w, detector centre): the emitter, its axis, two directions across
    it and the detector's centre, mm; ``sphere`` is (centre, radius), mm.
    """
    f, a, u, w, detector = sensor
    centre, radius_mm = sphere
    detector_radius = np.sqrt(model.detector_area_mm2 / np.pi)
    source_sigma = model.source_radius_mm / np.sqrt(2.0)
    slope_sigma = np.tan(np.deg2rad(model.divergence_deg)) / np.sqrt(2.0)
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
    mirrored = d - 2.0 * _dot(d, normal)[:, None] * normal
    mirror = _landing_counts(q, mirrored, f, a, detector, detector_radius)
    scattered = _perpendicular_basis(normal, rng.random((2, len(q))))
    return mirror, _landing_counts(q, scattered, f, a, detector, detector_radius)


def raytrace_coupling(
    sensor_mm,
    axis,
    detector_offset_mm,
    sphere_centre_mm,
    radius_mm,
    model,
    *,
    n_rays=2_000_000,
    seed=0,
):
    """Monte Carlo ray count of the mirror and Lambertian couplings (reflectance 1).

    Rays start at points drawn from a Gaussian source of 1/e radius ω0 in the sensor plane,
    with Gaussian slopes of 1/e width tan θ about the axis. Each is intersected with the
    exact sphere; its specular reflection and, independently, a cosine-weighted scattered
    ray from the same point are followed back to the sensor plane, and each is counted if it
    lands on the detector, a disc of area S_area centred at f + e.

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
    model : reflector_opt.model._sensors.SensorModel
        Supplies ω0, θ and S_area.
    n_rays : int, optional
        Rays traced (in chunks of 500,000).
    seed : int, optional
        Seed of the random generator.

    Returns
    -------
    (SurfaceCoupling, SurfaceCoupling)
        The detected fractions and their Monte Carlo standard errors.
    """
    rng = np.random.default_rng(seed)
    f = np.asarray(sensor_mm, dtype=float)
    a = unit(axis)
    u = unit_perpendicular(a)
    sensor = (f, a, u, np.cross(a, u), f + np.asarray(detector_offset_mm, dtype=float))
    sphere = (np.asarray(sphere_centre_mm, dtype=float), radius_mm)
    hits = np.zeros(2, dtype=np.int64)  # mirror, Lambertian
    for start in range(0, int(n_rays), 500_000):
        hits += _trace_chunk(rng, min(500_000, int(n_rays) - start), sensor, sphere, model)
    fractions = hits / n_rays
    errors = np.sqrt(fractions * (1.0 - fractions) / n_rays)
    return (
        SurfaceCoupling(mirror=fractions[0], lambertian=fractions[1]),
        SurfaceCoupling(mirror=errors[0], lambertian=errors[1]),
    )
