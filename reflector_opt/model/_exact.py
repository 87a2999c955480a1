"""Exact radiometric reference of the sensor–reflector coupling, by deterministic quadrature.

The yardstick of the fast model (:mod:`reflector_opt.model._optics`): it makes none of the fast
model's approximations and is far too slow for the optimiser's loop. It computes, for one
sensor and one pose, the power reaching the detector per unit emitted power for a surface of
reflectance 1 that is entirely mirror-like (``mirror``) or entirely Lambertian
(``lambertian``); a surface of reflectance ρ and specular fraction f couples
``ρ · [f · mirror + (1 − f) · lambertian]``.

The radiometric problem (docs/model.md, "Surface model" and "Exact reference"):

* **Emitter** — points x of the sensor plane (normal a, the optical axis) with the Gaussian
  density ``p(x) = exp(−|x|²/ω0²) / (π ω0²)``; each point emits rays whose slopes
  s = (v·u, v·w) / (v·a) have the Gaussian density ``q(s) = exp(−|s|²/T²) / (π T²)``,
  T = tan θ. The radiant intensity of a point is therefore ``I(v) = q(s) / (v·a)³`` (the
  solid angle is dΩ = (v·a)³ d²s); the total emitted power is 1.
* **Detector** — a disc of area S_area in the sensor plane centred at f + e; it collects every
  ray crossing it from the front (the irradiance of the plane integrated over the disc).
* **Mirror part** — for a source point x and a detector point D the reflecting point P is the
  unique specular point of the sphere (found by bisection in the plane through the centre,
  x and D), and the irradiance follows from the ray tube exactly (geometrical optics; the
  reflected wavefront of a point source off a sphere has principal curvatures
  ``1/s1 + 2/(R cos i)`` and ``1/s1 + 2 cos i/R``):
  ``E = I(v) · cos ψ / [(s1 + s2 + 2 s1 s2 /(R cos i)) (s1 + s2 + 2 s1 s2 cos i / R)]``,
  s1 = |P − x|, s2 = |D − P|, ψ the angle of the returning ray to the plane's normal.
* **Lambertian part** — the emitter's irradiance of the sphere, ``E(P) = Σ I(v) cos β / |P − x|²``
  integrated over the source, times the radiance factor 1/π and the detector's view
  ``cos β' cos ψ / |D − P|²``, integrated over the lit sphere (Gauss–Legendre in the polar angle
  about the sensor, uniform in azimuth).
* **Crosstalk** — the same two parts from one sensor's emitter to another sensor's detector
  (:func:`exact_cross_coupling`, :func:`exact_design_cross_coupling`): the emitter nodes are
  the first sensor's, the detector nodes the second's, and the detector's cos ψ is taken
  against its own axis. A mirror path needs its specular point seen from both ends; where
  the segment between them crosses the sphere there is none, and nothing is counted.

All integrals are products of Gauss rules (Gauss–Hermite over the source, Gauss–Legendre over
the disc and the sphere), so the result is deterministic; :func:`exact_coupling` takes the
orders, and tests/model/test_exact.py shows the convergence and the agreement with the Monte
Carlo ray count :func:`reflector_opt.model._reference.raytrace_coupling`;
tests/model/test_crosstalk.py checks the cross couplings against a hand-computed pair.
"""

import itertools

import numpy as np

from reflector_opt.model._geometry import rotate_centre, unit, unit_perpendicular
from reflector_opt.model._surface import SurfaceCoupling

#: Quadrature orders of the default reference: source points per axis (Gauss–Hermite),
#: detector rings × spokes, and sphere nodes in polar angle × azimuth. The convergence test
#: shows that doubling each changes the result by less than 1e-4 (relative).
DEFAULT_ORDERS = {"source": 6, "detector": (3, 8), "sphere": (96, 96)}


def _frame(axis, detector_offset_mm):
    a = unit(np.asarray(axis, dtype=float))
    e = np.asarray(detector_offset_mm, dtype=float)
    e = e - (e @ a) * a
    u = unit(e) if np.linalg.norm(e) > 0.0 else unit_perpendicular(a)
    return a, u, np.cross(a, u)


def gauss_hermite_2d(order, radius):
    """Nodes (N, 2) and weights (N,) of ∫ exp(−|x|²/r²)/(π r²) g(x) d²x."""
    z, w = np.polynomial.hermite.hermgauss(order)
    x, y = np.meshgrid(radius * z, radius * z, indexing="ij")
    weights = np.outer(w, w).ravel() / np.pi
    return np.stack([x.ravel(), y.ravel()], -1), weights


def _disc_rule(area_mm2, rings, spokes):
    """Nodes (N, 2) and weights (N,) of the mean over a disc of the given area."""
    radius = np.sqrt(area_mm2 / np.pi)
    z, w = np.polynomial.legendre.leggauss(rings)
    r = radius * np.sqrt(0.5 * (z + 1.0))  # Gauss–Legendre in r², uniform in area
    phi = 2.0 * np.pi * (np.arange(spokes) + 0.5) / spokes
    rr, pp = np.meshgrid(r, phi, indexing="ij")
    weights = np.repeat(0.5 * w, spokes) / spokes
    return np.stack([(rr * np.cos(pp)).ravel(), (rr * np.sin(pp)).ravel()], -1), weights


def _intensity(direction, a, u, w, slope):
    """Radiant intensity I(v) = q(s)/(v·a)³ of one emitter point, per unit power."""
    along = direction @ a
    ok = along > 0.0
    safe = np.where(ok, along, 1.0)
    s_sq = ((direction @ u) ** 2 + (direction @ w) ** 2) / safe**2
    q = np.exp(-s_sq / slope**2) / (np.pi * slope**2)
    return np.where(ok, q / safe**3, 0.0)


def specular_points(source, target, centre, radius, iterations=64):
    """Specular points of a sphere for pairs of outside points (bisection, exact to round-off).

    The reflecting point lies in the plane of the centre and both points, on the arc between
    their directions from the centre, where the tangential parts of the unit vectors to the
    two points cancel.
    """
    p = source - centre
    q = target - centre
    e1 = unit(p)
    q_perp = q - np.sum(q * e1, -1, keepdims=True) * e1
    q_perp_norm = np.linalg.norm(q_perp, axis=-1, keepdims=True)
    e2 = np.where(q_perp_norm > 1e-15, q_perp / np.where(q_perp_norm > 0, q_perp_norm, 1.0), 0.0)
    angle_q = np.arctan2(q_perp_norm[..., 0], np.sum(q * e1, -1))
    lo, hi = np.zeros_like(angle_q), angle_q

    def tangential(phi):
        c, s = np.cos(phi)[..., None], np.sin(phi)[..., None]
        point = radius * (c * e1 + s * e2)
        tangent = -s * e1 + c * e2
        return np.sum(tangent * unit(p - point), -1) + np.sum(tangent * unit(q - point), -1)

    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        positive = tangential(mid) > 0.0
        lo, hi = np.where(positive, mid, lo), np.where(positive, hi, mid)
    phi = 0.5 * (lo + hi)
    normal = np.cos(phi)[..., None] * e1 + np.sin(phi)[..., None] * e2
    return centre + radius * normal, normal


def mirror(sources, detectors, source_w, detector_w, centre, radius, detector_axis, intensity):
    """The perfect mirror: a ray tube at the exact specular point of each emitter/detector
    pair; ``intensity(v)`` is the emitter's radiant intensity towards unit directions v and
    ``detector_axis`` the optical axis of the detector's own sensor (its plane's normal is
    minus that axis)."""
    src = np.broadcast_to(sources[:, None, :], (len(sources), len(detectors), 3))
    det = np.broadcast_to(detectors[None, :, :], src.shape)
    point, normal = specular_points(src, det, centre, radius)
    to_source, to_detector = src - point, det - point
    s1 = np.linalg.norm(to_source, axis=-1)
    s2 = np.linalg.norm(to_detector, axis=-1)
    cos_i = np.sum(normal * to_source, -1) / s1
    cos_psi = -(to_detector @ detector_axis) / s2  # the returning ray against the normal −a
    # the detector sees P too (no specular point exists where the segment crosses the sphere)
    seen = np.sum(normal * to_detector, -1) > 0.0
    visible = (cos_i > 0.0) & (cos_psi > 0.0) & seen
    cos_i = np.where(visible, cos_i, 1.0)
    spread = (s1 + s2 + 2.0 * s1 * s2 / (radius * cos_i)) * (
        s1 + s2 + 2.0 * s1 * s2 * cos_i / radius
    )
    irradiance = intensity(-to_source / s1[..., None]) * cos_psi / spread
    irradiance = np.where(visible, irradiance, 0.0)
    return source_w @ irradiance @ detector_w


def sphere_rule(centre, radius, pole, cap, polar_nodes, azimuth_nodes):
    """Points, outward normals and area weights over a cap of the sphere about a pole."""
    b1 = unit_perpendicular(pole)
    b2 = np.cross(pole, b1)
    z, wz = np.polynomial.legendre.leggauss(polar_nodes)
    polar = 0.5 * cap * (z + 1.0)
    azimuth = 2.0 * np.pi * np.arange(azimuth_nodes) / azimuth_nodes
    pp, aa = np.meshgrid(polar, azimuth, indexing="ij")
    normal = (
        np.cos(pp)[..., None] * pole
        + (np.sin(pp) * np.cos(aa))[..., None] * b1
        + (np.sin(pp) * np.sin(aa))[..., None] * b2
    ).reshape(-1, 3)
    area = (radius**2 * np.sin(pp) * 0.5 * cap * wz[:, None] * 2.0 * np.pi / azimuth_nodes).ravel()
    return centre + radius * normal, normal, area


def lit_cap(sensor, a, centre, radius, slope):
    """Pole and angular radius of a cap that holds all of the beam's light on the sphere.

    The pole is the normal where the axis meets the sphere (or the point facing the sensor if
    it misses); the cap reaches the edge of the part visible from the sensor, or the edge of
    the cone of slopes up to 7 T (q < e⁻⁴⁹ beyond), whichever is nearer, plus a margin for the
    emitter's size and the detector's offset.
    """
    p = sensor - centre
    facing = unit(p)
    b = p @ a
    disc = b * b - (p @ p - radius**2)
    if disc >= 0.0 and b < 0.0:
        t = -b - np.sqrt(disc)
        pole = unit(p + t * a)
    else:
        t = np.linalg.norm(p) - radius
        pole = facing
    offset = np.arccos(np.clip(pole @ facing, -1.0, 1.0))
    visible = np.arccos(min(radius / np.linalg.norm(p), 1.0)) + offset
    beam = np.arcsin(min(1.0, (t + 2.0) * 7.0 * slope / radius))
    return pole, min(visible, 2.0 * beam, np.pi / 2.0)


def _lambertian(
    sources,
    detectors,
    source_w,
    detector_w,
    centre,
    radius,
    a,
    u,
    w,
    slope,
    orders,
    detector_axis,
):
    """The Lambertian sphere: the emitter's irradiance over the cap it lights, seen by the
    detector nodes, whose plane has the normal −``detector_axis``."""
    pole, cap = lit_cap(sources.mean(0), a, centre, radius, slope)
    point, normal, area = sphere_rule(centre, radius, pole, cap, *orders)
    irradiance = np.zeros(len(point))
    for x, weight in zip(sources, source_w, strict=True):
        to_source = x - point
        r = np.linalg.norm(to_source, axis=-1)
        cos_in = np.maximum(np.sum(normal * to_source, -1) / r, 0.0)
        irradiance += weight * _intensity(-to_source / r[:, None], a, u, w, slope) * cos_in / r**2
    return lambertian_detected(
        irradiance, point, normal, area, detectors, detector_w, detector_axis
    )


def sensor_nodes(sensor_mm, axis, detector_offset_mm, model, source_order, detector_order):
    """The sensor's frame and the quadrature nodes over its emitter and its detector disc.

    Parameters
    ----------
    sensor_mm : numpy.ndarray, shape (3,)
        Emitter centre f, mm.
    axis : array_like, shape (3,)
        Optical axis a.
    detector_offset_mm : array_like, shape (3,)
        Vector e from the emitter to the detector centre (its part along a is dropped), mm.
    model : reflector_opt.model._sensors.SensorModel
        Supplies ω0 and S_area.
    source_order : int
        Gauss–Hermite nodes per axis over the emitter.
    detector_order : (int, int)
        Rings and spokes over the detector disc.

    Returns
    -------
    tuple
        ``(a, u, w)`` the frame, then the emitter nodes (N, 3) mm and weights (N,), the
        detector nodes (M, 3) mm and weights (M,).
    """
    a, u, w = _frame(axis, detector_offset_mm)
    src_xy, src_w = gauss_hermite_2d(source_order, model.source_radius_mm)
    det_xy, det_w = _disc_rule(model.detector_area_mm2, *detector_order)
    detector_centre = sensor_mm + np.asarray(detector_offset_mm, dtype=float)
    detector_centre -= ((detector_centre - sensor_mm) @ a) * a
    sources = sensor_mm + src_xy[:, :1] * u + src_xy[:, 1:] * w
    detectors = detector_centre + det_xy[:, :1] * u + det_xy[:, 1:] * w
    return (a, u, w), sources, src_w, detectors, det_w


def lambertian_detected(irradiance, point, normal, area, detectors, detector_w, a):
    """Power a Lambertian surface sends to the detector: Σ E(P)/π · cos β' cos ψ/|D − P|² dA.

    Parameters
    ----------
    irradiance : numpy.ndarray
        Shape (N,): irradiance E at each surface node (per unit emitted power).
    point, normal : numpy.ndarray
        Shape (N, 3): the nodes and their outward normals, mm.
    area : numpy.ndarray
        Shape (N,): the nodes' area weights, mm².
    detectors : numpy.ndarray
        Shape (M, 3): detector points, mm.
    detector_w : numpy.ndarray
        Shape (M,): their weights (the mean over the disc).
    a : numpy.ndarray
        The optical axis of the detector's sensor (its plane's normal is −a).

    Returns
    -------
    float
        Detected irradiance averaged over the disc (times its area: the coupling).
    """
    detected = 0.0
    for d, weight in zip(detectors, detector_w, strict=True):
        to_detector = d - point
        r = np.linalg.norm(to_detector, axis=-1)
        cos_out = np.maximum(np.sum(normal * to_detector, -1) / r, 0.0)
        cos_psi = np.maximum(-(to_detector @ a) / r, 0.0)
        detected += weight * np.sum(irradiance * cos_out * cos_psi / r**2 * area) / np.pi
    return detected


def exact_coupling(
    sensor_mm,
    axis,
    detector_offset_mm,
    sphere_centre_mm,
    radius_mm,
    model,
    *,
    source_order=DEFAULT_ORDERS["source"],
    detector_order=DEFAULT_ORDERS["detector"],
    sphere_order=DEFAULT_ORDERS["sphere"],
):
    """Exact mirror and Lambertian couplings of one sensor at one pose (reflectance 1).

    See the module notes for the radiometric problem and the quadrature.

    Parameters
    ----------
    sensor_mm : array_like, shape (3,)
        Emitter centre f, mm.
    axis : array_like, shape (3,)
        Optical axis a, towards the reflector.
    detector_offset_mm : array_like, shape (3,)
        Vector e from the emitter to the detector centre (its part along a is dropped), mm.
    sphere_centre_mm : array_like, shape (3,)
        Sphere centre at the pose of interest, mm.
    radius_mm : float
        Sphere radius R, mm.
    model : reflector_opt.model._sensors.SensorModel
        Supplies ω0 (``source_radius_mm``), θ (``divergence_deg``) and S_area.
    source_order : int, optional
        Gauss–Hermite nodes per axis over the emitter.
    detector_order : (int, int), optional
        Rings and spokes of the rule over the detector disc.
    sphere_order : (int, int), optional
        Gauss–Legendre nodes in polar angle and uniform nodes in azimuth over the lit cap.

    Returns
    -------
    SurfaceCoupling
        Mirror and Lambertian couplings (floats), detected over emitted power.
    """
    return exact_cross_coupling(
        sensor_mm,
        axis,
        detector_offset_mm,
        sensor_mm,
        axis,
        detector_offset_mm,
        sphere_centre_mm,
        radius_mm,
        model,
        model,
        source_order=source_order,
        detector_order=detector_order,
        sphere_order=sphere_order,
    )


def exact_cross_coupling(
    emitter_mm,
    emitter_axis,
    emitter_offset_mm,
    receiver_mm,
    receiver_axis,
    receiver_offset_mm,
    sphere_centre_mm,
    radius_mm,
    emitter_model,
    receiver_model,
    *,
    source_order=DEFAULT_ORDERS["source"],
    detector_order=DEFAULT_ORDERS["detector"],
    sphere_order=DEFAULT_ORDERS["sphere"],
):
    """Exact mirror and Lambertian couplings from one sensor's LED to another's detector.

    Sensor j's emitter nodes, sensor k's detector nodes (a disc centred at f_k + e_k in k's
    plane, normal −a_k): the mirror part by the ray tube at each node pair's exact specular
    point, the Lambertian part over the cap j lights, both with cos ψ against k's own axis.
    For j = k this is :func:`exact_coupling`, bit for bit; a sensor in the sphere gives 0.

    Parameters
    ----------
    emitter_mm, emitter_axis, emitter_offset_mm : array_like, shape (3,)
        The emitting sensor j: emitter centre f_j (mm), optical axis a_j and its own
        emitter-to-detector vector e_j (mm; orients the emitter's nodes).
    receiver_mm, receiver_axis, receiver_offset_mm : array_like, shape (3,)
        The receiving sensor k: its emitter centre f_k (mm), optical axis a_k and e_k (mm);
        its detector disc is centred at f_k + e_k (e_k's part along a_k dropped).
    sphere_centre_mm, radius_mm : array_like, shape (3,), and float
        Sphere centre at the pose of interest and sphere radius R, mm.
    emitter_model, receiver_model : reflector_opt.model._sensors.SensorModel
        Sensor j's part (ω0, θ) and sensor k's (S_area).
    source_order, detector_order, sphere_order
        Quadrature orders, as for :func:`exact_coupling`.

    Returns
    -------
    SurfaceCoupling
        Mirror and Lambertian couplings (floats, reflectance 1): k's detected over j's emitted.
    """
    centre = np.asarray(sphere_centre_mm, dtype=float)
    f, g = np.asarray(emitter_mm, dtype=float), np.asarray(receiver_mm, dtype=float)
    slope = np.tan(np.deg2rad(emitter_model.divergence_deg))
    (a, u, w), sources, src_w, _, _ = sensor_nodes(
        f, emitter_axis, emitter_offset_mm, emitter_model, source_order, detector_order
    )
    (b, _, _), _, _, detectors, det_w = sensor_nodes(
        g, receiver_axis, receiver_offset_mm, receiver_model, source_order, detector_order
    )
    if min(np.linalg.norm(f - centre), np.linalg.norm(g - centre)) <= radius_mm:
        return SurfaceCoupling(mirror=0.0, lambertian=0.0)
    args = (sources, detectors, src_w, det_w, centre, radius_mm, a, u, w, slope)
    area = receiver_model.detector_area_mm2
    return SurfaceCoupling(
        mirror=area * float(mirror(*args[:6], b, lambda v: _intensity(v, a, u, w, slope))),
        lambertian=area * float(_lambertian(*args, sphere_order, b)),
    )


def exact_design_coupling(design, pitch_deg, roll_deg, **orders):
    """Exact mirror and Lambertian couplings of every sensor of a design at a few poses.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    pitch_deg, roll_deg : array_like
        Pose angles, degrees, broadcast to shape P (keep P small: each pose and sensor takes
        tens of milliseconds).
    **orders
        Quadrature orders passed to :func:`exact_coupling`.

    Returns
    -------
    SurfaceCoupling
        Arrays of shape ``P + (n_sensors,)``.
    """
    return design_couplings(exact_coupling, design, pitch_deg, roll_deg, **orders)


def exact_design_cross_coupling(design, pitch_deg, roll_deg, **orders):
    """Exact couplings from every sensor's LED to every sensor's detector at a few poses.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    pitch_deg, roll_deg : array_like
        Pose angles, degrees, broadcast to shape P (keep P small: each pose and pair takes
        tens of milliseconds to a second).
    **orders
        Quadrature orders passed to :func:`exact_cross_coupling`.

    Returns
    -------
    SurfaceCoupling
        Arrays of shape ``P + (n_sensors, n_sensors)``, reflectance 1: entry ``[..., k, j]``
        from emitter j to detector k; the diagonal is each sensor's own coupling, equal to
        :func:`exact_design_coupling`'s.
    """
    shape, centres, sensors = _design_poses(design, pitch_deg, roll_deg)
    mirror = np.zeros((*shape, len(sensors), len(sensors)))
    lambertian = np.zeros_like(mirror)
    pairs = list(itertools.product(enumerate(sensors), repeat=2))
    for index in np.ndindex(shape):
        for (k, (*receiver, receiver_model)), (j, (*emitter, emitter_model)) in pairs:
            result = exact_cross_coupling(
                *emitter,
                *receiver,
                centres[index],
                design.reflector.radius_mm,
                emitter_model,
                receiver_model,
                **orders,
            )
            mirror[(*index, k, j)] = result.mirror
            lambertian[(*index, k, j)] = result.lambertian
    return SurfaceCoupling(mirror=mirror, lambertian=lambertian)


def _design_poses(design, pitch_deg, roll_deg):
    """Pose shape P, the sphere centre at each pose (P + (3,), paper Eq 1) and each sensor's
    (position f, axis a, detector offset e, model)."""
    pitch, roll = np.broadcast_arrays(
        np.asarray(pitch_deg, dtype=float), np.asarray(roll_deg, dtype=float)
    )
    centres = rotate_centre(design.reflector.centre_mm, pitch, roll)
    sensors = [
        (
            placement.position_mm,
            placement.axis,
            model.emitter_detector_mm * placement.in_plane_detector_direction,
            model,
        )
        for placement, model in zip(design.sensors, design.models, strict=True)
    ]
    return pitch.shape, centres, sensors


def design_couplings(coupling, design, pitch_deg, roll_deg, **options):
    """A one-sensor, one-pose coupling evaluated for every sensor of a design at every pose.

    Parameters
    ----------
    coupling : callable
        ``coupling(sensor_mm, axis, detector_offset_mm, sphere_centre_mm, radius_mm, model,
        **options)`` → :class:`SurfaceCoupling` of floats, as :func:`exact_coupling`.
    design : reflector_opt.design._design.Design
    pitch_deg, roll_deg : array_like
        Pose angles, degrees, broadcast to shape P.
    **options
        Passed to ``coupling``.

    Returns
    -------
    SurfaceCoupling
        Arrays of shape ``P + (n_sensors,)``.
    """
    shape, centres, sensors = _design_poses(design, pitch_deg, roll_deg)
    mirror = np.zeros((*shape, len(sensors)))
    lambertian = np.zeros_like(mirror)
    for index in np.ndindex(shape):
        for s, (position, axis, offset, model) in enumerate(sensors):
            result = coupling(
                position, axis, offset, centres[index], design.reflector.radius_mm, model, **options
            )
            mirror[(*index, s)] = result.mirror
            lambertian[(*index, s)] = result.lambertian
    return SurfaceCoupling(mirror=mirror, lambertian=lambertian)
