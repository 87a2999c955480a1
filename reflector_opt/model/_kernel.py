"""The per-pose model as compiled scalar formulas, and the fused loop over poses.

Every formula the forward model evaluates per pose and per sensor is written here once, for
one pose and one sensor, and compiled with numba. The array functions of
:mod:`reflector_opt.model._geometry` and :mod:`reflector_opt.model._optics` apply these formulas
elementwise; :func:`pose_geometry` runs the geometry for every pose and sensor in a single
pass, and :func:`couplings_at` the surface's radiometry (:func:`surface_coupling`: exact
specular points and ray tubes for the mirror part, the lit cap for the Lambertian part, on
small Gauss rules).

All the compiled functions live in this one module on purpose: numba's on-disk cache of a
function is invalidated by changes to the file that defines it only, so a kernel that calls
formulas from another file could keep running an old copy of them.

Units: mm, radians inside; each function states its equation; docs/model.md derives them.
"""

import math
import os
import stat
import tempfile

import numba
import numpy as np

from reflector_opt.model import _rotation as rotation


def _probe():
    return 0


def _disk_cache():
    """Whether numba can cache this file's functions on disk, choosing the folder.

    The cache never goes beside the installed modules: files left in the package's
    ``__pycache__`` outlive an uninstall and turn the folder into an empty namespace package
    that hides a later (editable) install. Unless ``NUMBA_CACHE_DIR`` names a folder, it goes
    to this user's cache folder (``$XDG_CACHE_HOME`` or ``~/.cache``, then
    ``reflector_opt/numba``) or, if that cannot be had (a read-only home), to a folder of this
    user's in the temporary directory; ``NUMBA_CACHE_DIR`` is set for this process and the
    workers it starts. If no folder can be had, the functions are compiled afresh in every
    process.

    Returns
    -------
    bool
    """
    if os.environ.get("NUMBA_CACHE_DIR") and _cache_works():
        return True
    for folder in (_user_cache_folder(), _private_temp_folder()):
        if folder is None:
            continue
        numba.config.CACHE_DIR = os.environ["NUMBA_CACHE_DIR"] = folder
        if _cache_works():
            return True
    os.environ.pop("NUMBA_CACHE_DIR", None)
    numba.config.CACHE_DIR = ""
    return False


def _cache_works():
    try:
        numba.njit(cache=True)(_probe)
        return True
    except RuntimeError:
        return False


def _user_cache_folder():
    """``reflector_opt/numba`` in this user's cache folder, made if need be, or None."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    folder = os.path.join(base, "reflector_opt", "numba")
    try:
        os.makedirs(folder, mode=0o700, exist_ok=True)
        info = os.stat(folder)
    except OSError:
        return None
    owned = not hasattr(os, "getuid") or info.st_uid == os.getuid()
    return folder if stat.S_ISDIR(info.st_mode) and owned and not info.st_mode & 0o022 else None


def _private_temp_folder():
    """A folder of the temporary directory only this user can write, or None.

    The cache holds pickled code, so a folder that another user owns or can write is not
    used.
    """
    try:
        if not hasattr(os, "getuid"):
            return tempfile.mkdtemp(prefix="reflector_opt-numba-")
        folder = os.path.join(tempfile.gettempdir(), f"reflector_opt-numba-{os.getuid()}")
        os.makedirs(folder, mode=0o700, exist_ok=True)
        info = os.lstat(folder)
    except OSError:
        return None
    private = stat.S_ISDIR(info.st_mode) and info.st_uid == os.getuid()
    return folder if private and not info.st_mode & 0o022 else None


#: Cached on disk where possible (:func:`_disk_cache`); floating-point errors give inf/NaN as
#: in numpy; the compiler may reorder arithmetic, but NaN and inf keep their meaning (no
#: "nnan" or "ninf").
_OPTIONS = {
    "cache": _disk_cache(),
    "error_model": "numpy",
    "nogil": True,
    "fastmath": {"arcp", "contract", "afn", "reassoc", "nsz"},
}
_compile = numba.njit(**_OPTIONS)
#: The scalar formulas are inlined into the loops that call them.
_inline = numba.njit(inline="always", **_OPTIONS)
#: Newton steps of the specular-point search (quadratic convergence from the arc's middle).
_NEWTON_STEPS = 3


#: s1 = Rx(α) Ry(γ) s0 (paper Eq 1), :func:`reflector_opt.model._rotation.rotated_centre`.
rotated_centre = _inline(rotation.rotated_centre)


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
def _specular_angle(a_len, b1, b2, radius_mm):
    """Angle φ of the specular point on a circle for two points outside it (Newton).

    In the plane of the sphere's centre and both points, with the centre at the origin, the
    first point at (a_len, 0) and the second at (b1, b2), b2 ≥ 0: the reflecting point
    R(cos φ, sin φ) is where the unit vectors to the two points make equal angles with the
    normal, i.e. where the sum of their tangential parts h(φ) vanishes. Newton's method on
    h from the middle of the arc between the points, kept inside the arc.
    """
    arc = math.atan2(b2, b1)
    phi = 0.5 * arc
    for _ in range(_NEWTON_STEPS):
        c, s = math.cos(phi), math.sin(phi)
        ax, ay = a_len - radius_mm * c, -radius_mm * s
        bx, by = b1 - radius_mm * c, b2 - radius_mm * s
        per_a = 1.0 / math.sqrt(ax * ax + ay * ay)
        per_b = 1.0 / math.sqrt(bx * bx + by * by)
        tan_a, tan_b = (c * ay - s * ax) * per_a, (c * by - s * bx) * per_b
        nor_a, nor_b = (c * ax + s * ay) * per_a, (c * bx + s * by) * per_b
        slope = -(nor_a + nor_b) - radius_mm * (
            (1.0 - tan_a * tan_a) * per_a + (1.0 - tan_b * tan_b) * per_b
        )
        phi = min(max(phi - (tan_a + tan_b) / slope, 0.0), arc)
    return phi


@_inline
def emitter_intensity(d_a, d_u, d_w, slope):
    """Radiant intensity of an emitter point towards (d_a, d_u, d_w), per unit power, 1/sr.

    ``I = q(s) / cos³ γ`` with the Gaussian slope density ``q(s) = exp(−|s|²/T²) / (π T²)``,
    s = (d_u, d_w)/d_a the ray's slope and γ its angle to the axis (dΩ = cos³ γ d²s).
    Zero behind the sensor plane (d_a ≤ 0).
    """
    if d_a <= 0.0:
        return 0.0
    per_a = 1.0 / d_a
    s_sq = (d_u * d_u + d_w * d_w) * per_a * per_a
    cos_sq = 1.0 / (1.0 + s_sq)
    per_slope_sq = 1.0 / (slope * slope)
    return math.exp(-s_sq * per_slope_sq) * per_slope_sq / (math.pi * cos_sq * math.sqrt(cos_sq))


@_inline
def mirror_irradiance(c_a, c_u, c_w, radius_mm, x_u, x_w, y_u, y_w, slope):
    """Irradiance of the sensor plane at a point y by a mirror sphere and an emitter point x.

    Exact geometrical optics for a point source: the specular point P of the sphere (centre
    c, radius R) for x and y, and the ray-tube spreading of the reflected wavefront, whose
    principal curvatures are 1/s1 + 2/(R cos i) and 1/s1 + 2 cos i/R:
    ``E = I(P − x) · cos ψ / [(s1 + s2 + 2 s1 s2/(R cos i)) (s1 + s2 + 2 s1 s2 cos i/R)]``,
    s1 = ‖P − x‖, s2 = ‖y − P‖, ψ the returning ray's angle to the plane's normal.
    Coordinates: the sensor frame (a, u, w) with the emitter centre at the origin; x and y
    lie in the sensor plane. Per unit emitted power, 1/mm².
    """
    ga, gu, gw = -c_a, x_u - c_u, x_w - c_w  # x − c
    a_len = math.sqrt(ga * ga + gu * gu + gw * gw)
    e1a, e1u, e1w = ga / a_len, gu / a_len, gw / a_len
    ha, hu, hw = -c_a, y_u - c_u, y_w - c_w  # y − c
    b1 = ha * e1a + hu * e1u + hw * e1w
    qa, qu, qw = ha - b1 * e1a, hu - b1 * e1u, hw - b1 * e1w
    b2 = math.sqrt(qa * qa + qu * qu + qw * qw)
    if b2 > 1e-12 * a_len:
        e2a, e2u, e2w = qa / b2, qu / b2, qw / b2
        phi = _specular_angle(a_len, b1, b2, radius_mm)
    else:
        e2a, e2u, e2w, phi = 0.0, 0.0, 0.0, 0.0
    cos_phi, sin_phi = math.cos(phi), math.sin(phi)
    na, nu, nw = (
        cos_phi * e1a + sin_phi * e2a,
        cos_phi * e1u + sin_phi * e2u,
        cos_phi * e1w + sin_phi * e2w,
    )
    pa, pu, pw = c_a + radius_mm * na, c_u + radius_mm * nu, c_w + radius_mm * nw
    ia, iu, iw = pa, pu - x_u, pw - x_w  # P − x
    s1 = math.sqrt(ia * ia + iu * iu + iw * iw)
    ra, ru, rw = -pa, y_u - pu, y_w - pw  # y − P
    s2 = math.sqrt(ra * ra + ru * ru + rw * rw)
    cos_i = -(na * ia + nu * iu + nw * iw) / s1
    cos_psi = pa / s2
    if not (cos_i > 0.0 and cos_psi > 0.0):
        return 0.0
    k = 2.0 * s1 * s2 / radius_mm
    spread = (s1 + s2 + k / cos_i) * (s1 + s2 + k * cos_i)
    return emitter_intensity(ia, iu, iw, slope) * cos_psi / spread


@_inline
def lit_cap(c_a, c_u, c_w, radius_mm, slope, margin_mm):
    """Pole (unit vector) and angular radius of a cap of the sphere that holds the beam's light.

    The pole is the normal where the optical axis meets the sphere (the point facing the
    emitter if it misses); the cap reaches the edge of the part seen from the emitter, or
    the edge of the patch lit by slopes up to 7 T (q < e⁻⁴⁹ beyond) widened by the margin,
    whichever is nearer.
    """
    pa, pu, pw = -c_a, -c_u, -c_w  # emitter − centre
    distance = math.sqrt(pa * pa + pu * pu + pw * pw)
    disc = pa * pa - (distance * distance - radius_mm * radius_mm)
    if disc >= 0.0 and pa < 0.0:
        t = -pa - math.sqrt(disc)
        oa, ou, ow = (pa + t) / radius_mm, pu / radius_mm, pw / radius_mm
    else:
        t = distance - radius_mm
        oa, ou, ow = pa / distance, pu / distance, pw / distance
    facing = (oa * pa + ou * pu + ow * pw) / distance
    offset = math.acos(min(max(facing, -1.0), 1.0))
    visible = math.acos(min(radius_mm / distance, 1.0)) + offset
    lit = math.asin(min(1.0, (7.0 * slope * (t + margin_mm) + margin_mm) / radius_mm))
    return oa, ou, ow, min(visible, 2.0 * lit, 0.5 * math.pi)


@_inline
def _reach_mm(sources, detectors):
    """How far the emitter and detector points reach from the emitter's centre, mm."""
    margin = 0.0
    for k in range(sources.shape[0]):
        margin = max(margin, math.sqrt(sources[k, 0] ** 2 + sources[k, 1] ** 2))
    for k in range(detectors.shape[0]):
        margin = max(margin, math.sqrt(detectors[k, 0] ** 2 + detectors[k, 1] ** 2))
    return margin


@_inline
def _perpendicular_pair(oa, ou, ow):
    """A right-handed orthonormal basis (b1, b2) of the plane perpendicular to the unit
    vector o, as six components (b1a, b1u, b1w, b2a, b2u, b2w)."""
    if abs(oa) <= abs(ou) and abs(oa) <= abs(ow):
        h = oa
        b1a, b1u, b1w = 1.0 - h * oa, -h * ou, -h * ow
    elif abs(ou) <= abs(ow):
        h = ou
        b1a, b1u, b1w = -h * oa, 1.0 - h * ou, -h * ow
    else:
        h = ow
        b1a, b1u, b1w = -h * oa, -h * ou, 1.0 - h * ow
    norm = math.sqrt(b1a * b1a + b1u * b1u + b1w * b1w)
    b1a, b1u, b1w = b1a / norm, b1u / norm, b1w / norm
    b2a, b2u, b2w = ou * b1w - ow * b1u, ow * b1a - oa * b1w, oa * b1u - ou * b1a
    return b1a, b1u, b1w, b2a, b2u, b2w


@_inline
def lambertian_irradiance(c_a, c_u, c_w, radius_mm, sources, detectors, polar, azimuth, slope):
    """Mean irradiance of the detector by a Lambertian sphere of albedo 1, 1/mm².

    ``E = ∫ E_s(P) · cos β' cos ψ / (π |y − P|²) dA`` over the lit cap, with the sphere's
    irradiance ``E_s(P) = Σ_k w_k I(P − x_k) cos β / |P − x_k|²`` from the emitter points x_k
    and the mean over the detector points y_l; Gauss–Legendre in the cap's polar angle,
    uniform in azimuth.

    Parameters
    ----------
    sources, detectors : numpy.ndarray, shape (K, 3)
        Rows (u, w, weight) of the emitter and detector points in the sensor plane.
    polar : numpy.ndarray, shape (M, 2)
        Gauss–Legendre nodes and weights on [0, 1] for the polar angle over the cap.
    azimuth : numpy.ndarray, shape (N, 2)
        cos and sin of the azimuth nodes, equally spaced.
    slope : float
        T = tan θ.
    """
    oa, ou, ow, cap = lit_cap(c_a, c_u, c_w, radius_mm, slope, _reach_mm(sources, detectors))
    b1a, b1u, b1w, b2a, b2u, b2w = _perpendicular_pair(oa, ou, ow)
    step = 2.0 * math.pi / azimuth.shape[0]
    per_slope_sq = 1.0 / (slope * slope)
    total = 0.0
    for i in range(polar.shape[0]):
        angle = cap * polar[i, 0]
        cos_p, sin_p = math.cos(angle), math.sin(angle)
        ring = radius_mm * radius_mm * sin_p * cap * polar[i, 1] * step
        for j in range(azimuth.shape[0]):
            ca, sa = azimuth[j, 0], azimuth[j, 1]
            na = cos_p * oa + sin_p * (ca * b1a + sa * b2a)
            nu = cos_p * ou + sin_p * (ca * b1u + sa * b2u)
            nw = cos_p * ow + sin_p * (ca * b1w + sa * b2w)
            pa, pu, pw = c_a + radius_mm * na, c_u + radius_mm * nu, c_w + radius_mm * nw
            if pa <= 0.0:  # behind the sensor plane: no emitter light
                continue
            # I(P − x)·cos β/|P − x|³ = q(s)·cos β/p_a³: the 1/cos³γ of the intensity is
            # |P − x|³/p_a³ (p_a is the same for every emitter point).
            per_a_sq = 1.0 / (pa * pa)
            lit = 0.0
            for k in range(sources.shape[0]):
                du, dw = pu - sources[k, 0], pw - sources[k, 1]
                cos_in = -(na * pa + nu * du + nw * dw)
                if cos_in > 0.0:
                    s_sq = (du * du + dw * dw) * per_a_sq
                    lit += sources[k, 2] * math.exp(-s_sq * per_slope_sq) * cos_in
            if lit == 0.0:
                continue
            lit *= per_slope_sq / (math.pi * pa * pa * pa)
            seen = 0.0
            for k in range(detectors.shape[0]):
                du, dw = detectors[k, 0] - pu, detectors[k, 1] - pw
                r_sq = pa * pa + du * du + dw * dw
                cos_out = nu * du + nw * dw - na * pa
                if cos_out > 0.0:
                    seen += detectors[k, 2] * cos_out * pa / (r_sq * r_sq)
            total += ring * lit * seen
    return total / math.pi


@_inline
def surface_coupling(c_a, c_u, c_w, radius_mm, specular_fraction, optics, rules):
    """Mirror and Lambertian couplings of one sensor at one pose, per unit reflectance.

    The exact radiometry of :mod:`reflector_opt.model._exact` on small Gauss rules: the emitter
    and the detector disc as a few weighted points, the mirror part by exact specular points
    and ray tubes, the Lambertian part over the lit cap. A part whose share is zero is not
    computed.

    Parameters
    ----------
    c_a, c_u, c_w : float
        Sphere centre in the sensor frame (a, u, w), emitter centre at the origin, mm.
    radius_mm : float
        Sphere radius R, mm.
    specular_fraction : float
        f; the mirror part is skipped at 0 and the Lambertian part at 1.
    optics : numpy.ndarray, shape (2,)
        tan θ and the detector area S_area (mm²).
    rules : tuple
        (sources, detectors, polar, azimuth) as for :func:`lambertian_irradiance`, the
        emitter and detector points already scaled to this sensor.

    Returns
    -------
    (float, float)
        η_mirror and η_Lambert, detected over emitted power.
    """
    sources, detectors, polar, azimuth = rules
    slope, area = optics[0], optics[1]
    if c_a * c_a + c_u * c_u + c_w * c_w <= radius_mm * radius_mm:
        return 0.0, 0.0  # the emitter inside the sphere: a collision, no light path
    mirror = 0.0
    if specular_fraction > 0.0:
        for k in range(sources.shape[0]):
            for m in range(detectors.shape[0]):
                mirror += (
                    sources[k, 2]
                    * detectors[m, 2]
                    * mirror_irradiance(
                        c_a,
                        c_u,
                        c_w,
                        radius_mm,
                        sources[k, 0],
                        sources[k, 1],
                        detectors[m, 0],
                        detectors[m, 1],
                        slope,
                    )
                )
    lambertian = 0.0
    if specular_fraction < 1.0:
        lambertian = lambertian_irradiance(
            c_a, c_u, c_w, radius_mm, sources, detectors, polar, azimuth, slope
        )
    return area * mirror, area * lambertian


@_compile
def couplings_at(
    centres, radius_mm, specular_fraction, optics, sources, detectors, polar, azimuth, out
):
    """:func:`surface_coupling` of every sensor at every pose.

    Parameters
    ----------
    centres : numpy.ndarray, shape (N, S, 3)
        Sphere centre in each sensor's frame (emitter at the origin) at each pose, mm.
    radius_mm, specular_fraction : float
        R (mm) and f.
    optics : numpy.ndarray, shape (S, 2)
        Per sensor: tan θ and S_area (mm²).
    sources, detectors : numpy.ndarray, shape (S, K, 3)
        Per sensor: emitter and detector points (u, w in mm) and weights.
    polar : numpy.ndarray, shape (M, 2)
        Polar-angle rule on [0, 1].
    azimuth : numpy.ndarray, shape (N, 2)
        cos and sin of the azimuth nodes.
    out : numpy.ndarray, shape (2, N, S)
        Receives η_mirror and η_Lambert.
    """
    for i in range(centres.shape[0]):
        for s in range(centres.shape[1]):
            out[0, i, s], out[1, i, s] = surface_coupling(
                centres[i, s, 0],
                centres[i, s, 1],
                centres[i, s, 2],
                radius_mm,
                specular_fraction,
                optics[s],
                (sources[s], detectors[s], polar, azimuth),
            )


@_compile
def pose_geometry(
    cos_pitch, sin_pitch, cos_roll, sin_roll, centre_mm, sensor_mm, frames, radius_mm, out
):
    """Eq 3 distance, axial distance and the sphere centre in each sensor's frame, every pose.

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
    out : numpy.ndarray, shape (5, M, N, S)
        Filled with the Eq 3 distance d (mm), the axial distance t (mm; NaN where the axis
        misses) and the sphere centre s1 − f in the sensor frame (a, u, w), mm.
    """
    x, y, z = centre_mm[0], centre_mm[1], centre_mm[2]
    # sensors outermost, so that each sensor's constants stay in registers over the poses
    for s in range(sensor_mm.shape[0]):
        f_x, f_y, f_z = sensor_mm[s, 0], sensor_mm[s, 1], sensor_mm[s, 2]
        a_x, a_y, a_z = frames[s, 0, 0], frames[s, 0, 1], frames[s, 0, 2]
        u_x, u_y, u_z = frames[s, 1, 0], frames[s, 1, 1], frames[s, 1, 2]
        w_x, w_y, w_z = frames[s, 2, 0], frames[s, 2, 1], frames[s, 2, 2]
        for i in range(cos_pitch.shape[0]):
            for j in range(cos_pitch.shape[1]):
                s1_x, s1_y, s1_z = rotated_centre(
                    x, y, z, cos_pitch[i, j], sin_pitch[i, j], cos_roll[i, j], sin_roll[i, j]
                )
                p_x, p_y, p_z = f_x - s1_x, f_y - s1_y, f_z - s1_z
                p_a = p_x * a_x + p_y * a_y + p_z * a_z
                p_u = p_x * u_x + p_y * u_y + p_z * u_z
                p_w = p_x * w_x + p_y * w_y + p_z * w_z
                surface, t, _, _, _ = axis_hit(p_a, p_u, p_w, radius_mm)
                out[0, i, j, s] = surface
                out[1, i, j, s] = t
                out[2, i, j, s] = -p_a
                out[3, i, j, s] = -p_u
                out[4, i, j, s] = -p_w


@_compile
def tensor_series_grid(left, coefficients, right, out):
    """``out[i, l, t] = Σ_jk left[i, j] c[j, k, t] right[l, k]``: a series on a grid.

    Parameters
    ----------
    left : numpy.ndarray, shape (M, n)
    coefficients : numpy.ndarray, shape (n, n, T)
    right : numpy.ndarray, shape (N, n)
    out : numpy.ndarray, shape (M, N, T)
    """
    n, terms = coefficients.shape[1], coefficients.shape[2]
    partial = np.empty((n, terms))
    for i in range(left.shape[0]):
        for k in range(n):
            for t in range(terms):
                acc = 0.0
                for j in range(left.shape[1]):
                    acc += left[i, j] * coefficients[j, k, t]
                partial[k, t] = acc
        for m in range(right.shape[0]):
            for t in range(terms):
                acc = 0.0
                for k in range(n):
                    acc += partial[k, t] * right[m, k]
                out[i, m, t] = acc


@_compile
def tensor_series(left, coefficients, right, out):
    """``out[i, t] = Σ_jk left[i, j] c[j, k, t] right[i, k]``: a series at scattered points.

    Parameters
    ----------
    left, right : numpy.ndarray, shape (N, n)
    coefficients : numpy.ndarray, shape (n, n, T)
    out : numpy.ndarray, shape (N, T)
    """
    n, terms = coefficients.shape[1], coefficients.shape[2]
    for i in range(left.shape[0]):
        for t in range(terms):
            acc = 0.0
            for j in range(n):
                inner = 0.0
                for k in range(n):
                    inner += coefficients[j, k, t] * right[i, k]
                acc += left[i, j] * inner
            out[i, t] = acc


@_compile
def axis_hits(p_a, p_u, p_w, radius_mm, out):
    """:func:`axis_hit` over 1-D arrays of p's components; ``out`` (5, N) receives its results."""
    for i in range(p_a.size):
        out[0, i], out[1, i], out[2, i], out[3, i], out[4, i] = axis_hit(
            p_a[i], p_u[i], p_w[i], radius_mm
        )
