"""The compiled surface couplings: hand values and the exact reference on a lab curve.

The exact reference over the whole search space of every part: tests/model/test_search_space.py.
"""

import numpy as np
from numpy.testing import assert_allclose
from scipy.special import exp1

from reflector_opt.model._exact import exact_coupling
from reflector_opt.model._optics import beam_radius, flat_target_coupling, surface_couplings
from reflector_opt.model._sensors import NJL5901R_2 as NJL

#: A point emitter and a point detector beside it (S_area tiny, e tiny).
POINT = NJL.with_(source_radius_mm=1e-6, detector_area_mm2=1e-8, emitter_detector_mm=1e-6)
SLOPE = np.tan(np.deg2rad(NJL.divergence_deg))


def test_beam_radius_hand_values():
    assert_allclose(beam_radius(0.0, 0.15, 30.0), 0.15)
    assert_allclose(beam_radius(2.0, 0.0, 45.0), 2.0)
    assert_allclose(beam_radius(1.0, 0.3, 45.0), np.hypot(0.3, 1.0))


def test_flat_mirror_point_source_is_the_image_source():
    """A flat mirror at d returns I(0)/(2d)² on the axis: q(0) = 1/(π T²)."""
    d = np.array([0.5, 1.0, 2.5])
    expected = POINT.detector_area_mm2 / (np.pi * SLOPE**2) / (2.0 * d) ** 2
    # the flat target is a sphere of 1e5 mm: (1 + d/R)² differs from 1 by up to 5e-5
    assert_allclose(flat_target_coupling(d, POINT, 1.0, 1.0), expected, rtol=1e-4)


def test_sphere_mirror_point_source_on_axis():
    """Convex mirror of radius R at normal incidence: E = I(0) / (2d (1 + d/R))²."""
    d, radius = 1.3, 6.0
    centre = np.array([[[d + radius, 0.0, 0.0]]])
    eta = surface_couplings(centre, radius, 1.0, [POINT]).mirror[0, 0]
    expected = POINT.detector_area_mm2 / (np.pi * SLOPE**2) / (2.0 * d * (1.0 + d / radius)) ** 2
    assert_allclose(eta, expected, rtol=1e-6)


def test_flat_lambertian_point_source_closed_form():
    """On-axis Lambertian plane: E = λ (1 − λ e^λ E1(λ)) / (π d²), λ = 1/T².

    From E = ∫ q(s) cos⁴γ d²s / (π d²) with cos⁴γ = 1/(1 + s²)² and the Gaussian slope
    density q; the integral is the exponential integral E1.
    """
    lam = 1.0 / SLOPE**2
    d = np.array([0.7, 1.5, 3.0])
    expected = lam * (1.0 - lam * np.exp(lam) * exp1(lam)) / (np.pi * d**2)
    eta = flat_target_coupling(d, POINT, 1.0, 0.0) / POINT.detector_area_mm2
    assert_allclose(eta, expected, rtol=2e-3)
    exact = exact_coupling([0, 0, 0], [1, 0, 0], [0, 0, 1e-6], [1.5 + 1e5, 0, 0], 1e5, POINT)
    assert_allclose(exact.lambertian / POINT.detector_area_mm2, expected[1], rtol=1e-4)


def test_reflectance_and_fraction_mix_the_parts_linearly():
    d = np.array([0.6, 1.8])
    mirror = flat_target_coupling(d, NJL, 1.0, 1.0)
    matte = flat_target_coupling(d, NJL, 1.0, 0.0)
    assert_allclose(flat_target_coupling(d, NJL, 0.8, 0.25), 0.8 * (0.25 * mirror + 0.75 * matte))


def test_flat_mirror_curve_rises_then_falls_with_its_peak_below_the_range():
    d = np.linspace(0.1, 3.0, 59)
    eta = flat_target_coupling(d, NJL, 0.9, 1.0)
    peak = d[np.argmax(eta)]
    assert 0.2 < peak < NJL.range_mm[0]
    assert np.all(np.diff(eta[d > NJL.range_mm[0]]) < 0)


def test_flat_target_coupling_agrees_with_the_exact_reference_over_a_lab_curve():
    """The finer flat-target rules hold the curve's shape to 0.15 % from 0.3 mm, 0.02 % from
    0.5 mm: what fitting a material's specular fraction to a measured curve needs."""
    d = np.array([0.3, 0.4, 0.5, 1.0, 2.0, 4.0])
    exact = [
        exact_coupling([0, 0, 0], [1, 0, 0], [0, 0, 0.5], [x + 1e5, 0, 0], 1e5, NJL) for x in d
    ]
    for f, part in ((1.0, "mirror"), (0.0, "lambertian")):
        ratio = flat_target_coupling(d, NJL, 1.0, f) / [getattr(e, part) for e in exact]
        assert np.all(np.abs(ratio - 1.0) < 1.5e-3), part
        assert np.all(np.abs(ratio[d >= 0.5] - 1.0) < 2e-4), part


def test_a_part_with_no_share_is_not_computed():
    centre = np.array([[[8.0, 0.2, 0.1]]])
    assert surface_couplings(centre, 7.0, 1.0, [NJL]).lambertian[0, 0] == 0.0
    assert surface_couplings(centre, 7.0, 0.0, [NJL]).mirror[0, 0] == 0.0
    assert surface_couplings(centre, 7.0, 0.5, [NJL]).mirror[0, 0] > 0.0
