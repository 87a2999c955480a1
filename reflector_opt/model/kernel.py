"""The per-pose model as compiled scalar formulas, and the fused loop over poses.

Every formula the forward model evaluates per pose and per sensor is written here once, for
one pose and one sensor, and compiled with numba. The array functions of
:mod:`reflector_opt.model.geometry` and :mod:`reflector_opt.model.optics` apply these formulas
elementwise, and :func:`respond_poses` runs them back to back for every pose and sensor in a
single pass, so no pose-sized temporary is ever written to memory.

All the compiled functions live in this one module on purpose: numba's on-disk cache of a
function is invalidated by changes to the file that defines it only, so a kernel that calls
formulas from another file could keep running an old copy of them.

Units: mm, radians inside; each function states its equation; docs/model.md derives them.
"""

from __future__ import annotations

import math

import numba

__all__ = [
    "axis_hit",
    "axis_hits",
    "coupling_and_spot",
    "coupling_ufunc",
    "respond_poses",
    "rotated_centre",
    "round_trip_radius_sq",
]

#: Cached on disk; floating-point errors give inf/NaN as in numpy; the compiler may reorder
#: arithmetic, but NaN and inf keep their meaning (no "nnan" or "ninf").
_OPTIONS = {
    "cache": True,
    "error_model": "numpy",
    "nogil": True,
    "fastmath": {"arcp", "contract", "afn", "reassoc", "nsz"},
}
_compile = numba.njit(**_OPTIONS)
#: The scalar formulas are inlined into the loops that call them.
_inline = numba.njit(inline="always", **_OPTIONS)


@_inline
def rotated_centre(x, y, z, cos_pitch, sin_pitch, cos_roll, sin_roll):
    """Reflector centre after rotation, s1 = Rx(α) Ry(γ) s0 (paper Eq 1), component-wise.

    Parameters
    ----------
    x, y, z : float
        Sphere centre s0 at zero pose, mm.
    cos_pitch, sin_pitch, cos_roll, sin_roll : float
        cos γ, sin γ, cos α, sin α.

    Returns
    -------
    (float, float, float)
        s1, mm.
    """
    z_after_pitch = z * cos_pitch - x * sin_pitch
    return (
        x * cos_pitch + z * sin_pitch,
        y * cos_roll - z_after_pitch * sin_roll,
        y * sin_roll + z_after_pitch * cos_roll,
    )


@_inline
def axis_hit(p_a, p_u, p_w, radius_mm):
    """Eq 3 distance and the first intersection of a sensor's optical axis with the sphere.

    With p = f − s1 = (p_a, p_u, p_w) in the sensor frame (a, u, w), the shortest distance is
    ``d = ‖p‖ − r_s`` (paper Eq 3) and the axis f + t·a meets the sphere first at
    ``t = −p_a − sqrt(r_s² − p_u² − p_w²)``, where the outward normal is
    ``n = (−sqrt(r_s² − p_u² − p_w²), p_u, p_w) / r_s``.

    Parameters
    ----------
    p_a, p_u, p_w : float
        Components of p = f − s1 along the sensor's axis a and in-plane directions u, w, mm.
    radius_mm : float
        Sphere radius r_s, mm.

    Returns
    -------
    (float, float, float, float, float)
        d (mm), t (mm; NaN where the axis misses the sphere) and the normal's components
        (n_a, n_u, n_w) (n_a NaN where it misses).
    """
    lateral_sq = p_u * p_u + p_w * p_w
    surface = math.sqrt(p_a * p_a + lateral_sq) - radius_mm
    depth_sq = radius_mm * radius_mm - lateral_sq
    depth = math.sqrt(depth_sq) if depth_sq >= 0.0 and p_a < 0.0 else math.nan
    per_radius = 1.0 / radius_mm
    return surface, -p_a - depth, -depth * per_radius, p_u * per_radius, p_w * per_radius


@_inline
def round_trip_radius_sq(outward_mm, return_mm, mirror_power, source_radius_mm, slope):
    """Squared 1/e radius after free space t, a mirror of power P (1/mm) and free space t' back.

    The ray-transfer matrix ``[[1 + t'P, t + t' + t t' P], [P, 1 + t'P]]`` maps a Gaussian
    source of 1/e radius ω0 and slope spread tan θ to
    ``ω² = ((1 + t'P) ω0)² + ((t + t' + t t' P) tan θ)²`` (Gaussian widths add in quadrature).

    Parameters
    ----------
    outward_mm, return_mm : float
        t and t', mm.
    mirror_power : float
        P = 2/R (normal incidence) or its tangential/sagittal form, 1/mm; 0 for a flat mirror.
    source_radius_mm : float
        ω0, mm.
    slope : float
        tan θ.

    Returns
    -------
    float
        ω², mm².

    References
    ----------
    A. E. Siegman, *Lasers* (1986), ch. 15.
    """
    a = (1.0 + return_mm * mirror_power) * source_radius_mm
    b = (outward_mm + return_mm + outward_mm * return_mm * mirror_power) * slope
    return a * a + b * b


@_inline
def coupling_and_spot(
    axial_distance_mm,
    normal_a,
    normal_u,
    normal_w,
    detector_offset_mm,
    source_radius_mm,
    slope,
    detector_area_mm2,
    reflectance,
    curvature,
):
    """Coupling η and spot offset ‖Δ‖ for one sensor at one pose (paper Eq 4 extended).

    ``η = ρ · S_area · K / (π ω_t ω_s) · exp(−(m_t cos 2i)²/ω_t² − m_s²/ω_s²)``. The reflected
    axis comes back to the sensor plane displaced by ‖Δ‖ = t tan 2i along the plane of
    incidence τ = n⊥/sin i; m = Δ − e (e the detector offset along u) splits into m_t along
    τ and m_s across it. ω_t and ω_s are the returning beam's tangential and sagittal 1/e
    radii at the detector, for mirror powers 2/(R cos i) and 2 cos i/R and the return length
    t/cos 2i − m_t sin 2i (the detector's own distance down the beam);
    K = cos 2i (1 + m_t sin 2i / ℓ_t) is the obliquity of the sensor plane, ℓ_t the detector's
    distance from the tangential virtual source. At normal incidence τ is taken as u.

    Parameters
    ----------
    axial_distance_mm : float
        Distance t along the optical axis to the reflector, mm (NaN: the axis misses).
    normal_a, normal_u, normal_w : float
        Outward unit normal at the hit in the sensor frame (a, u, w).
    detector_offset_mm : float
        ‖e‖, mm.
    source_radius_mm : float
        Emitter 1/e radius ω0, mm.
    slope : float
        tan θ, θ the emitter's 1/e half-angle.
    detector_area_mm2 : float
        S_area, mm².
    reflectance : float
        ρ (0–1).
    curvature : float
        2/R, 1/mm (0 for a flat mirror).

    Returns
    -------
    (float, float)
        η (0 where the axis misses or the beam does not return, i ≥ 45°) and ‖Δ‖ in mm (NaN
        there).

    References
    ----------
    Osman et al. (2024), Eq 4; docs/model.md for the extension.
    """
    t = axial_distance_mm
    cos_i = -normal_a
    cos_2i = 2.0 * cos_i * cos_i - 1.0
    if not (cos_2i > 0.0 and math.isfinite(t)):
        return 0.0, math.nan
    sec_2i = 1.0 / cos_2i
    sin_i = math.sqrt(normal_u * normal_u + normal_w * normal_w)
    sin_2i = 2.0 * sin_i * cos_i
    spot = t * sin_2i * sec_2i
    if sin_i > 0.0:
        per_sin_i = 1.0 / sin_i
        along, across = normal_u * per_sin_i, normal_w * per_sin_i
    else:
        along, across = 1.0, 0.0
    miss_t = spot - detector_offset_mm * along
    miss_s = detector_offset_mm * across
    t_back = t * sec_2i - miss_t * sin_2i
    power_t, power_s = curvature / cos_i, curvature * cos_i
    w_t_sq = round_trip_radius_sq(t, t_back, power_t, source_radius_mm, slope)
    w_s_sq = round_trip_radius_sq(t, t_back, power_s, source_radius_mm, slope)
    # ℓ_t = t / (1 + t P_t) + t_back, the detector's distance from the virtual source
    lens = 1.0 + t * power_t
    obliquity = cos_2i * max(1.0 + miss_t * sin_2i * lens / (t + t_back * lens), 0.0)
    per_w_t_sq, per_w_s_sq = 1.0 / w_t_sq, 1.0 / w_s_sq
    miss_t_cos = miss_t * cos_2i
    exponent = miss_t_cos * miss_t_cos * per_w_t_sq + miss_s * miss_s * per_w_s_sq
    peak = reflectance * detector_area_mm2 / math.pi * math.sqrt(per_w_t_sq * per_w_s_sq)
    eta = obliquity * peak * math.exp(-exponent)
    return (eta if math.isfinite(eta) else 0.0), spot


@_compile
def respond_poses(
    cos_pitch,
    sin_pitch,
    cos_roll,
    sin_roll,
    centre_mm,
    sensor_mm,
    frames,
    radius_mm,
    optics,
    reflectance,
    out,
):
    """Distance, axial distance, spot offset and coupling of every sensor at every pose.

    Parameters
    ----------
    cos_pitch, sin_pitch, cos_roll, sin_roll : numpy.ndarray, shape (M, N)
        cos γ, sin γ, cos α, sin α of the poses, laid out in two dimensions (broadcast
        views with zero strides are fine: a pitch × roll grid needs no copies).
    centre_mm : numpy.ndarray, shape (3,)
        s0, mm.
    sensor_mm : numpy.ndarray, shape (S, 3)
        Sensor positions f, mm.
    frames : numpy.ndarray, shape (S, 3, 3)
        Sensor frames, rows a, u, w.
    radius_mm : float
        r_s, mm.
    optics : numpy.ndarray, shape (S, 4)
        Per sensor: detector offset ‖e‖ (mm), ω0 (mm), tan θ, S_area (mm²).
    reflectance : float
        ρ.
    out : numpy.ndarray, shape (4, M, N, S)
        Filled with the Eq 3 distance d (mm), the axial distance t (mm), the spot offset
        ‖Δ‖ (mm) and the coupling η.
    """
    curvature = 2.0 / radius_mm
    x, y, z = centre_mm[0], centre_mm[1], centre_mm[2]
    # sensors outermost, so that each sensor's constants stay in registers over the poses
    for s in range(sensor_mm.shape[0]):
        f_x, f_y, f_z = sensor_mm[s, 0], sensor_mm[s, 1], sensor_mm[s, 2]
        a_x, a_y, a_z = frames[s, 0, 0], frames[s, 0, 1], frames[s, 0, 2]
        u_x, u_y, u_z = frames[s, 1, 0], frames[s, 1, 1], frames[s, 1, 2]
        w_x, w_y, w_z = frames[s, 2, 0], frames[s, 2, 1], frames[s, 2, 2]
        offset, source_radius, slope, area = optics[s, 0], optics[s, 1], optics[s, 2], optics[s, 3]
        for i in range(cos_pitch.shape[0]):
            for j in range(cos_pitch.shape[1]):
                s1_x, s1_y, s1_z = rotated_centre(
                    x, y, z, cos_pitch[i, j], sin_pitch[i, j], cos_roll[i, j], sin_roll[i, j]
                )
                p_x, p_y, p_z = f_x - s1_x, f_y - s1_y, f_z - s1_z
                surface, t, n_a, n_u, n_w = axis_hit(
                    p_x * a_x + p_y * a_y + p_z * a_z,
                    p_x * u_x + p_y * u_y + p_z * u_z,
                    p_x * w_x + p_y * w_y + p_z * w_z,
                    radius_mm,
                )
                eta, spot = coupling_and_spot(
                    t, n_a, n_u, n_w, offset, source_radius, slope, area, reflectance, curvature
                )
                out[0, i, j, s] = surface
                out[1, i, j, s] = t
                out[2, i, j, s] = spot
                out[3, i, j, s] = eta


@_compile
def axis_hits(p_a, p_u, p_w, radius_mm, out):
    """:func:`axis_hit` over 1-D arrays of p's components; ``out`` (5, N) receives its results."""
    for i in range(p_a.size):
        out[0, i], out[1, i], out[2, i], out[3, i], out[4, i] = axis_hit(
            p_a[i], p_u[i], p_w[i], radius_mm
        )


@numba.vectorize(cache=True)
def coupling_ufunc(
    axial_distance_mm,
    normal_a,
    normal_u,
    normal_w,
    detector_offset_mm,
    source_radius_mm,
    slope,
    detector_area_mm2,
    reflectance,
    curvature,
):
    """The coupling η of :func:`coupling_and_spot` as a broadcasting numpy ufunc."""
    return coupling_and_spot(
        axial_distance_mm,
        normal_a,
        normal_u,
        normal_w,
        detector_offset_mm,
        source_radius_mm,
        slope,
        detector_area_mm2,
        reflectance,
        curvature,
    )[0]
