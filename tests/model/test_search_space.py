"""The fast model against the exact reference over the whole search space of every part.

225 designs (25 for each of the 9 catalogue parts, tests/model/search_space.py), at a
workspace corner and a random pose each, wherever a sensor is in its usable range (about 800
sensor–pose pairs). The tolerances are those docs/model.md §8 states:

* every pair, both regimes: the mirror part within 1 % where it carries at least 2 % of the
  light; where it carries less (the detector in the far wing of the returning spot, a tail
  the fast model's 2 × 2 emitter points do not resolve: up to 13 % off here, 32 % in the
  documented run) its error is within 0.5 % of the whole coupling (measured 0.06 % here,
  0.41 % in the documented run);
* designs whose whole distance window is in range (the designs the optimiser can return):
  the Lambertian part within 2.5 % (the parts with a wide beam and 1.4 mm between LED and
  detector, EE-SY193 and TCRT1000, reach 2.3 %); over each part's pairs the 95th percentile
  of either part's error is below 0.5 % (measured at most 0.3 %), so an error confined to a
  corner of the space fails too; the pose interpolation of ``forward.respond`` within 0.25 %
  (0.04 % for every part but CNY70, whose 56° beam reaches 0.15 %);
* designs that leave the range or come near the sphere at some pose: the Lambertian part
  within 5 % (documented up to 4.2 %); the pose interpolation within 10 % of each sensor's
  largest coupling (measured 6.8 %), the domain's boundary (those touching the sphere, which
  ``respond`` refuses, left out).
"""

import numpy as np
import pytest

from reflector_opt.model import _forward as forward
from reflector_opt.model._exact import exact_coupling
from reflector_opt.model._geometry import rotate_centre
from reflector_opt.model._interpolation import PoseBox
from reflector_opt.model._optics import surface_couplings
from tests.model.search_space import frame_centres, sampled_designs, workspace_distances

#: Orders of the reference: within 1e-4 of the module's default orders on these designs
#: (docs/model.md §8), a fraction of the tolerances below.
ORDERS = {"source_order": 4, "detector_order": (2, 6), "sphere_order": (64, 64)}
#: Relative tolerances (see the module's docstring).
MIRROR, LAMBERTIAN_IN_WINDOW, LAMBERTIAN_OUTSIDE, PERCENTILE_95 = 0.01, 0.025, 0.05, 0.005
#: Mirror share of the light below which the mirror part is held to the whole coupling.
RESOLVED_MIRROR_SHARE = 0.02
#: Its error then, relative to the whole coupling (mirror + Lambertian).
UNRESOLVED_MIRROR = 5e-3
INTERPOLATION, OUTSIDE_INTERPOLATION = 2.5e-3, 0.1


def _pair(sample, pose, sensor):
    """Fast and exact (mirror, Lambertian) of one sensor–pose pair."""
    design, (pitch, roll) = sample.design, pose
    centre = frame_centres(design, pitch, roll)[sensor][None, None, :]
    model = design.models[sensor]
    fast = surface_couplings(centre, design.reflector.radius_mm, 0.5, [model])
    placement = design.sensors[sensor]
    exact = exact_coupling(
        placement.position_mm,
        placement.axis,
        model.emitter_detector_mm * placement.in_plane_detector_direction,
        rotate_centre(design.reflector.centre_mm, pitch, roll),
        design.reflector.radius_mm,
        model,
        **ORDERS,
    )
    return (
        np.array([fast.mirror[0, 0], fast.lambertian[0, 0]]),
        np.array([exact.mirror, exact.lambertian]),
    )


@pytest.fixture(scope="module")
def couplings():
    """Per kept pair: part, window flag, fast and exact (mirror, Lambertian)."""
    rows = []
    for sample in sampled_designs():
        for pose, sensor in zip(sample.poses, sample.sensors, strict=True):
            fast, exact = _pair(sample, pose, sensor)
            rows.append((sample.part, sample.window_in_range, fast, exact))
    return rows


def test_the_sample_covers_every_part_both_regimes_and_the_whole_bounds():
    samples = sampled_designs()
    parts = {s.part for s in samples}
    assert len(samples) >= 200 and len(parts) == 9
    assert sum(s.window_in_range for s in samples) >= 50
    assert sum(not s.window_in_range for s in samples) >= 50
    radii = np.array([s.design.reflector.radius_mm for s in samples])
    assert radii.max() - radii.min() > 4.0


def _errors(rows):
    """Relative errors (n, 2) of (mirror, Lambertian); the mirror's relative to the whole
    coupling where it carries less than 2 % of the light."""
    fast = np.array([r[2] for r in rows])
    exact = np.array([r[3] for r in rows])
    error = fast / exact - 1.0
    total = exact.sum(axis=1)
    unresolved = exact[:, 0] < RESOLVED_MIRROR_SHARE * total
    error[unresolved, 0] = (fast - exact)[unresolved, 0] / total[unresolved]
    scale = np.where(unresolved, UNRESOLVED_MIRROR / MIRROR, 1.0)
    return error, scale


def _worst(rows, error):
    i, part = np.unravel_index(np.argmax(np.abs(error)), error.shape)
    return f"{rows[i][0]}: {('mirror', 'Lambertian')[part]} {error[i, part]:+.3%}"


def test_the_mirror_part_agrees_over_the_whole_sample(couplings):
    error, scale = _errors(couplings)
    mirror = error[:, :1] / scale[:, None]
    assert np.abs(mirror).max() < MIRROR, _worst(couplings, mirror)


def test_the_lambertian_part_agrees_on_the_designs_with_the_window_in_range(couplings):
    rows = [r for r in couplings if r[1]]
    error = _errors(rows)[0] * [0.0, 1.0]
    assert np.abs(error).max() < LAMBERTIAN_IN_WINDOW, _worst(rows, error)


def test_the_lambertian_part_agrees_on_the_designs_that_leave_the_window(couplings):
    rows = [r for r in couplings if not r[1]]
    error = _errors(rows)[0] * [0.0, 1.0]
    assert np.abs(error).max() < LAMBERTIAN_OUTSIDE, _worst(rows, error)


@pytest.mark.parametrize("part", sorted({s.part for s in sampled_designs()}))
def test_95_percent_of_each_parts_pairs_agree_to_half_a_percent(couplings, part):
    rows = [r for r in couplings if r[0] == part]
    error, scale = _errors(rows)
    error[:, 0] /= scale
    assert np.percentile(np.abs(error).max(axis=1), 95) < PERCENTILE_95


def _workspace_poses(design, rng, n):
    (p_lo, p_hi), (r_lo, r_hi) = design.workspace.pitch_deg, design.workspace.roll_deg
    return rng.uniform(p_lo, p_hi, n), rng.uniform(r_lo, r_hi, n)


def _interpolation_errors(sample, rng):
    """|interpolated − direct| at 60 random poses, and the directly computed couplings."""
    pitch, roll = _workspace_poses(sample.design, rng, 60)
    assert PoseBox.around(pitch, roll).nodes ** 2 < pitch.size  # the interpolated path
    interpolated = forward.respond(sample.design, pitch, roll).coupling
    direct = [  # 20 poses or fewer: computed at each pose
        forward.respond(sample.design, p, r).coupling
        for p, r in zip(pitch.reshape(3, 20), roll.reshape(3, 20), strict=True)
    ]
    direct = np.concatenate(direct)
    return np.abs(interpolated - direct), direct


def test_pose_interpolation_over_the_designs_that_leave_the_window():
    """The domain's boundary: where a sensor leaves its range or nears the sphere the coupling
    changes too fast over the workspace for 7 × 7 points, and may fall to nothing outside the
    beam. Held to 10 % of each sensor's largest coupling over the poses (measured 6.8 %;
    relative to the coupling at the pose 8.5 %, and without bound where it is 1e-7)."""
    rng = np.random.default_rng(6)
    worst = 0.0
    for sample in sampled_designs():
        distance = workspace_distances(sample.design)
        if sample.window_in_range or not np.all(np.isfinite(distance)):
            continue  # in range, or touching the sphere (respond refuses those poses)
        error, direct = _interpolation_errors(sample, rng)
        worst = max(worst, (error / direct.max(axis=0)).max())
    assert worst < OUTSIDE_INTERPOLATION, worst


def test_pose_interpolation_over_the_designs_with_the_window_in_range():
    """``respond`` on 60 poses interpolates over 7 × 7 Chebyshev points; on 20 poses or fewer it
    computes every pose directly. The coupling of the design's own surface is compared."""
    rng = np.random.default_rng(5)
    worst = 0.0
    for sample in sampled_designs():
        if sample.window_in_range:
            error, direct = _interpolation_errors(sample, rng)
            worst = max(worst, (error / direct).max())
    assert worst < INTERPOLATION, worst
