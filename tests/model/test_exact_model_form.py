"""The exact reference extended by a rough lobe, sub-surface spread and other emitter patterns."""

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.signal import fftconvolve
from scipy.special import exp1

from reflector_opt.model._exact import exact_coupling
from reflector_opt.model._exact_model_form import (
    cosine_power_exponent,
    emitter_intensity,
    exact_model_form_coupling,
    exact_model_form_design_coupling,
    two_gaussian_slopes,
)
from reflector_opt.model._sensors import NJL5901R_2 as NJL
from reflector_opt.util._errors import InputError

# (radius, tilt of the normal at the axis hit towards the detector side, distance), as in
# tests/model/test_exact.py
GEOMETRIES = [(1e5, 0.0, 1.0), (6.0, 0.0, 0.5), (6.0, -15.0, 1.0), (9.0, 10.0, 3.0)]
ORDERS = {"source_order": 4, "detector_order": (2, 6), "sphere_order": (24, 24)}
THETA = NJL.divergence_deg
SLOPE = np.tan(np.deg2rad(THETA))
#: A point emitter and a point detector: the flat-target closed forms hold for them.
POINT = NJL.with_(source_radius_mm=1e-7, detector_area_mm2=1e-10)


def _setting(radius, tilt_deg, distance, offset=0.5):
    normal = np.array([-np.cos(np.deg2rad(tilt_deg)), 0.0, np.sin(np.deg2rad(tilt_deg))])
    centre = np.array([distance, 0.0, 0.0]) - radius * normal
    return np.zeros(3), np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, offset]), centre, radius


def _per_area(coupling):
    """Irradiance of a point detector per unit emitted power, 1/mm²."""
    return coupling / POINT.detector_area_mm2


# --- the emitter patterns ---------------------------------------------------------------


def test_cosine_power_exponent_and_width_by_hand():
    # cos 30.8° = 0.858960, ln = −0.152029: m = 6.5777
    assert cosine_power_exponent(30.8) == pytest.approx(6.5777, abs=1e-3)
    m = cosine_power_exponent(THETA)
    assert np.cos(np.deg2rad(THETA)) ** m == pytest.approx(np.exp(-1.0))
    # mean-square slope 2/(m − 1) = 0.35857 against tan²θ = 0.35553: within 1 %
    assert 2.0 / (m - 1.0) == pytest.approx(SLOPE**2, rel=0.01)
    shares, widths = two_gaussian_slopes(THETA)
    assert shares.sum() == pytest.approx(1.0)
    assert shares @ widths**2 == pytest.approx(SLOPE**2)  # the same mean-square slope
    assert widths[1] == pytest.approx(np.sqrt(1.84) * SLOPE)  # (1 − 0.7 · 0.8²) / 0.3 = 1.84


@pytest.mark.parametrize("pattern", ["gaussian", "cosine_power", "two_gaussian"])
def test_every_pattern_emits_unit_power_and_nothing_backwards(pattern):
    def ring(gamma):
        v = np.array([np.cos(gamma), np.sin(gamma), 0.0])
        return 2.0 * np.pi * emitter_intensity(v, [1, 0, 0], THETA, pattern) * np.sin(gamma)

    total, _ = quad(ring, 0.0, np.pi / 2, limit=200)
    assert total == pytest.approx(1.0, abs=1e-6)
    assert emitter_intensity([-1.0, 0.0, 0.0], [1, 0, 0], THETA, pattern) == 0.0


def test_on_axis_intensities_by_hand():
    axis = np.array([0.0, 0.0, 1.0])
    gaussian = emitter_intensity(axis, axis, THETA, "gaussian")
    cosine = emitter_intensity(axis, axis, THETA, "cosine_power")
    assert gaussian == pytest.approx(1.0 / (np.pi * SLOPE**2))  # 0.8953
    assert cosine == pytest.approx((cosine_power_exponent(THETA) + 1.0) / (2.0 * np.pi))  # 1.206
    assert cosine / gaussian == pytest.approx(1.347, abs=1e-3)


def test_patterns_against_flat_target_closed_forms():
    """Point emitter and detector at the same point, 1 mm from a flat target.

    Mirror: the image source, E = I(0)/(2d)². Lambertian: E = (m + 1)/((m + 5) π d²) for
    the cosine power (∫ (m+1)/(2π) cos^(m+7)γ /(π d⁴) dA), and λ(1 − λ e^λ E1(λ))/(π d²),
    λ = 1/T², for the Gaussian (docs/model.md, §6).
    """
    args = (*_setting(1e7, 0.0, 1.0, offset=0.0), POINT)
    m = cosine_power_exponent(THETA)
    lam = 1.0 / SLOPE**2
    for pattern, on_axis, lambert in [
        ("cosine_power", (m + 1) / (2 * np.pi), (m + 1) / ((m + 5) * np.pi)),
        ("gaussian", 1 / (np.pi * SLOPE**2), lam * (1 - lam * np.exp(lam) * exp1(lam)) / np.pi),
    ]:
        got = exact_model_form_coupling(*args, emitter_pattern=pattern)
        assert _per_area(got.mirror) == pytest.approx(on_axis / 4.0, rel=1e-5)
        assert _per_area(got.lambertian) == pytest.approx(lambert, rel=1e-4)


@pytest.mark.parametrize("geometry", GEOMETRIES)
def test_other_patterns_give_similar_not_identical_couplings(geometry):
    args = (*_setting(*geometry), NJL)
    gauss = exact_coupling(*args, **ORDERS).total(0.9, 0.05)
    for pattern in ("cosine_power", "two_gaussian"):
        other = exact_model_form_coupling(*args, emitter_pattern=pattern, **ORDERS).total(0.9, 0.05)
        assert 0.003 < abs(other / gauss - 1.0) < 0.15


# --- every option at zero is the exact reference ----------------------------------------


@pytest.mark.parametrize("geometry", GEOMETRIES)
def test_no_extra_physics_is_the_exact_reference(geometry):
    args = (*_setting(*geometry), NJL)
    exact = exact_coupling(*args, **ORDERS)
    same = exact_model_form_coupling(*args, **ORDERS)
    assert same.mirror == pytest.approx(exact.mirror, rel=1e-12)
    assert same.lambertian == pytest.approx(exact.lambertian, rel=1e-12)


@pytest.mark.parametrize("geometry", GEOMETRIES)
def test_vanishing_roughness_and_spread_approach_the_exact_reference(geometry):
    args = (*_setting(*geometry), NJL)
    exact = exact_coupling(*args, **ORDERS)
    errors = [
        exact_model_form_coupling(*args, roughness_deg=r, **ORDERS).mirror / exact.mirror - 1.0
        for r in (3.0, 0.3, 0.003)
    ]
    assert abs(errors[2]) < 1e-7
    assert abs(errors[0]) > 50 * abs(errors[1])  # O(m²)
    spread = exact_model_form_coupling(*args, subsurface_mm=1e-5, **ORDERS).lambertian
    assert spread == pytest.approx(exact.lambertian, rel=1e-6)


# --- the rough lobe ----------------------------------------------------------------------


def test_rough_lobe_against_flat_target_integral():
    """Point emitter and detector together over a flat target: with t = tan γ,

    E = (1/(2 d²)) ∫ exp(−t²/T² − t²/m²) (1 + t²) t dt / (π T² m²)

    (I(γ) D(h) cos ψ / (4 ρ⁴) over the plane; h is the direction back to the point), which is
    the mirror's I(0)/(2d)² times T²/(T² + m²) · (1 + T² m²/(T² + m²)): 0.9950 for m = tan 3°,
    0.9459 for m = tan 10°.
    """
    d = 1.0
    args = (*_setting(1e7, 0.0, d, offset=0.0), POINT)
    mirror = 1.0 / (4 * np.pi * SLOPE**2 * d**2)
    for roughness in (3.0, 10.0):
        m = np.tan(np.deg2rad(roughness))

        def integrand(t, m=m):
            g = np.exp(-(t**2) / SLOPE**2 - t**2 / m**2) * (1 + t**2) * t
            return g / (np.pi * SLOPE**2 * m**2)

        hand = quad(integrand, 0.0, 20 * m)[0] / (2 * d**2)
        got = _per_area(exact_model_form_coupling(*args, roughness_deg=roughness).mirror)
        assert got == pytest.approx(hand, rel=1e-5)
        assert got < mirror
        closed = SLOPE**2 / (SLOPE**2 + m**2) * (1 + SLOPE**2 * m**2 / (SLOPE**2 + m**2))
        assert hand / mirror == pytest.approx(closed, rel=1e-9)
    assert hand / mirror == pytest.approx(0.9459, abs=1e-4)  # m = tan 10° = 0.176


def _brute_force_lobe(sensor, axis, offset, centre, radius, roughness_deg):
    """The lobe by a fine polar grid over the sphere about the point facing the pair."""
    m = np.tan(np.deg2rad(roughness_deg))
    x = np.asarray(sensor, float)
    y = x + np.asarray(offset, float)
    mid = 0.5 * (x + y) - centre
    pole = mid / np.linalg.norm(mid)
    b1 = np.cross(pole, [0.0, 1.0, 0.0])
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(pole, b1)
    z, wz = np.polynomial.legendre.leggauss(400)
    cap = 0.25
    polar = 0.5 * cap * (z + 1)
    azimuth = 2 * np.pi * (np.arange(720) + 0.5) / 720
    pp, aa = np.meshgrid(polar, azimuth, indexing="ij")
    n = (
        np.cos(pp)[..., None] * pole
        + (np.sin(pp) * np.cos(aa))[..., None] * b1
        + (np.sin(pp) * np.sin(aa))[..., None] * b2
    )
    area = radius**2 * np.sin(pp) * (0.5 * cap * wz)[:, None] * (2 * np.pi / 720)
    p = centre + radius * n
    to_x, to_y = x - p, y - p
    r1, r2 = np.linalg.norm(to_x, axis=-1), np.linalg.norm(to_y, axis=-1)
    h = to_x / r1[..., None] + to_y / r2[..., None]
    h /= np.linalg.norm(h, axis=-1)[..., None]
    c = np.sum(h * n, -1)
    tan_sq = (1 - c**2) / c**2
    lobe = np.exp(-tan_sq / m**2) / (np.pi * m**2 * c**4)
    intensity = emitter_intensity(-to_x / r1[..., None], axis, THETA, "gaussian")
    cos_psi = -(to_y @ np.asarray(axis, float)) / r2
    return np.sum(intensity / r1**2 * lobe / 4 * cos_psi / r2**2 * area)


@pytest.mark.parametrize("geometry", [(6.0, -15.0, 1.0), (9.0, 10.0, 2.0)])
def test_rough_lobe_on_a_curved_oblique_target_against_brute_force(geometry):
    setting = _setting(*geometry)
    got = _per_area(exact_model_form_coupling(*setting, POINT, roughness_deg=5.0).mirror)
    assert got == pytest.approx(_brute_force_lobe(*setting, 5.0), rel=1e-4)


# --- the sub-surface spread --------------------------------------------------------------


def test_spread_against_a_convolution_on_a_flat_target():
    """An independent path: the flat target's irradiance on a 5 µm grid, convolved with the
    sampled kernel by FFT, seen by a point detector 0.5 mm beside a point emitter at 1 mm.
    The spread lowers the coupling here (the light moves away from where the detector sees
    best) by 3.7 % at ℓ = 0.1 mm; the two paths agree on the ratio to 2e-4 (2e-6 found).
    """
    d, e, ell, h = 1.0, 0.5, 0.1, 0.005
    g = np.arange(-4.0, 4.0 + h / 2, h)
    yy, zz = np.meshgrid(g, g, indexing="ij")
    rho_sq = d**2 + yy**2 + zz**2
    direction = np.stack([np.full_like(yy, d), yy, zz], -1) / np.sqrt(rho_sq)[..., None]
    lit = emitter_intensity(direction, [1, 0, 0], THETA) * (d / np.sqrt(rho_sq)) / rho_sq
    k = np.arange(-1.5, 1.5 + h / 2, h)
    ky, kz = np.meshgrid(k, k, indexing="ij")
    kernel = np.exp(-np.hypot(ky, kz) / ell)
    blurred = fftconvolve(lit, kernel / kernel.sum(), mode="same")
    view = d**2 / (np.pi * (d**2 + yy**2 + (zz - e) ** 2) ** 2)
    grid_ratio = np.sum(blurred * view) / np.sum(lit * view)

    args = (*_setting(1e5, 0.0, d, offset=e), POINT)
    plain = exact_model_form_coupling(*args).lambertian
    spread = exact_model_form_coupling(*args, subsurface_mm=ell).lambertian
    assert spread / plain == pytest.approx(grid_ratio, abs=2e-4)
    assert 0.94 < spread / plain < 0.97


def test_spread_moves_light_outwards_but_keeps_it():
    """On a flat target the spread lowers the coupling near the lit patch's centre and raises
    it far from it (a detector 3 mm aside); at 3 mm from a flat target the patch is wide
    and the spread changes little."""
    near = (*_setting(1e5, 0.0, 1.0, offset=0.5), POINT)
    far_aside = (*_setting(1e5, 0.0, 1.0, offset=3.0), POINT)
    distant = (*_setting(1e5, 0.0, 3.0, offset=0.5), POINT)
    change = {
        name: exact_model_form_coupling(*a, subsurface_mm=0.1, **ORDERS).lambertian
        / exact_model_form_coupling(*a, **ORDERS).lambertian
        - 1.0
        for name, a in [("near", near), ("aside", far_aside), ("distant", distant)]
    }
    assert change["near"] < -0.02
    assert change["aside"] > 0.0
    assert -0.01 < change["distant"] < 0.0


def test_converged_in_the_lobe_and_spread_orders():
    args = (*_setting(6.0, -15.0, 1.0), NJL)
    options = {"roughness_deg": 3.0, "subsurface_mm": 0.1, "emitter_pattern": "cosine_power"}
    default = exact_model_form_coupling(*args, **options, **ORDERS)
    finer = exact_model_form_coupling(
        *args, **options, **ORDERS, lobe_order=10, spread_order=(8, 16)
    )
    assert default.mirror == pytest.approx(finer.mirror, rel=1e-5)
    assert default.lambertian == pytest.approx(finer.lambertian, rel=1e-4)


def test_design_wrapper_and_bad_options(design):
    result = exact_model_form_design_coupling(
        design, [0.0, 5.0], 0.0, roughness_deg=3.0, subsurface_mm=0.1, **ORDERS
    )
    assert result.mirror.shape == result.lambertian.shape == (2, 2)
    assert np.all(result.mirror > 0) and np.all(result.lambertian > 0)
    for bad in ({"roughness_deg": -1.0}, {"subsurface_mm": 5.0}, {"emitter_pattern": "flat"}):
        with pytest.raises(InputError):
            exact_model_form_design_coupling(design, 0.0, 0.0, **bad)
