"""How far to correct (asbuilt.stepsearch): the cubature points of the batch mean's
uncertainty, the part the process is predicted to print and the constraint it breaks.

The batch means here are stand-ins holding what these functions read (the names, prior
stds, posterior mean and determined directions of a pooling.BatchMean; for choose_step
also a batch's unit blocks and surfaces); choose_step on a real batch is tested in
test_correction.py."""

from types import SimpleNamespace

import numpy as np
import pytest

from reflector_opt.asbuilt._batch import geometry_names
from reflector_opt.asbuilt._correction import Correction, changed_geometry
from reflector_opt.asbuilt._parameters import ParameterLayout
from reflector_opt.asbuilt._stepsearch import (
    BISECTIONS,
    choose_step,
    posterior_points,
    predicted_print,
    print_problem,
)
from reflector_opt.design import Reflector, default_design
from reflector_opt.util._errors import InputError
from tests.asbuilt.printloop import drawn_design

NAMES = geometry_names(2)


def _mean(mean=None, directions=()):
    prior = np.linspace(0.05, 0.7, len(NAMES))
    batch = SimpleNamespace(names=NAMES, prior_std=prior)
    change = np.zeros(len(NAMES)) if mean is None else mean
    return SimpleNamespace(batch=batch, mean=change, directions=list(directions))


def test_the_cubature_points_hold_the_posteriors_mean_and_covariance():
    rng = np.random.default_rng(2)
    basis, _ = np.linalg.qr(rng.normal(size=(len(NAMES), 3)))
    directions = [
        SimpleNamespace(std=s, weights=basis[:, i]) for i, s in enumerate((0.5, 0.2, 1.0))
    ]
    mean = _mean(directions=directions)
    points = posterior_points(mean)
    assert points.shape == (6, len(NAMES))
    # Σ s_i² (v_i ∘ prior)(v_i ∘ prior)ᵀ, in mm and degrees: the 2k points with weight 1/(2k).
    scaled = [d.std * d.weights * mean.batch.prior_std for d in directions]
    covariance = sum(np.outer(v, v) for v in scaled)
    np.testing.assert_allclose(points.mean(axis=0), 0.0, atol=1e-15)
    np.testing.assert_allclose(points.T @ points / len(points), covariance, atol=1e-15)
    assert posterior_points(_mean()).tolist() == [[0.0] * len(NAMES)]  # nothing determined


def test_the_predicted_print_is_the_drawing_with_the_batch_mean_on_it():
    change = np.zeros(len(NAMES))
    change[NAMES.index("reflector_radius_mm")] = 0.05
    change[NAMES.index("reflector_centre_z_mm")] = -0.1
    printed = predicted_print(drawn_design(), _mean(change))
    assert printed.reflector.radius_mm == pytest.approx(9.05, abs=1e-12)
    assert printed.reflector.centre_mm == pytest.approx((0.0, 0.0, -1.3), abs=1e-12)
    assert printed.sensors == drawn_design().sensors


def test_print_problem_names_the_first_wall_below_the_minimum():
    assert print_problem(drawn_design(), _mean()) is None  # centre 1.2 mm below O: printable
    assert print_problem(default_design(), _mean()) is None  # 1.4 mm: a shell of 0.813 mm
    thin = default_design().replace(reflector=Reflector(centre_mm=(0.0, 0.0, -1.5)))
    problem = print_problem(thin, _mean())  # the default's earlier centre: 0.751 mm
    assert (
        problem
        == "reflector: the reflecting shell is 0.751 mm thick, below the printable minimum 0.8 mm"
    )
    # A print that moves the drawn centre down to 1.5 mm thins the shell the same way.
    change = np.zeros(len(NAMES))
    change[NAMES.index("reflector_centre_z_mm")] = -0.3
    assert print_problem(drawn_design(), _mean(change)) == problem


def _drawable(standoff_mm):
    """Whether the drawn design with sensor 1's seat moved by ``standoff_mm`` is a design."""
    change = np.zeros(len(NAMES))
    change[NAMES.index("sensor_1_standoff_mm")] = standoff_mm
    try:
        changed_geometry(drawn_design(), NAMES, change)
    except InputError:
        return False
    return True


def test_a_step_whose_next_batch_is_not_a_design_is_not_weighed():
    """One unit printed with sensor 1's seat 0.5 mm low and a correction that draws it 0.6 mm
    lower at step 1: every drawing is a design, but the unit printed again from it puts the
    sensor inside the sphere beyond the step α* where 0.5 + 0.6 α* mm reaches the limit of
    the drawing itself (found here by bisection on the drawing, not on the units). The search
    stops there and says why, in place of an InputError from the expected loss."""
    design = drawn_design()
    j = NAMES.index("sensor_1_standoff_mm")
    layout = ParameterLayout(design, 1)
    block = np.zeros(len(layout.unit_names))
    block[layout.unit_names.index("sensor_1_standoff_mm")] = -0.5
    mean = _mean(
        directions=[SimpleNamespace(std=1e-6, estimate=1.0, weights=np.eye(len(NAMES))[j])]
    )
    mean.batch.blocks, mean.batch.surfaces = [block], [np.zeros(len(layout.shared_names))]
    mean.batch.prior_std[j] = 0.6  # full change 0.6 mm: the drawing's seat 0.6 α mm lower
    correction = Correction(mean, (1.0,), 0.0, 0.0, 2.0, 0.95, (True,))
    np.testing.assert_allclose(correction.full_change[j], 0.6)
    assert all(_drawable(-0.6 * a) for a in (0.0, 0.5, 1.0)) and not _drawable(-1.1)
    inside, drawable = -1.1, -0.5  # the limit of the seat's move, by bisection on the drawing
    for _ in range(30):
        middle = 0.5 * (inside + drawable)
        inside, drawable = (inside, middle) if _drawable(middle) else (middle, drawable)
    edge = (-drawable - 0.5) / 0.6  # the step α* at which the unit's seat reaches it
    assert 0.25 < edge < 0.75

    cut, losses = choose_step(design, correction)
    weighed = max(losses)
    assert sorted(losses)[:-1] == [a for a in (0.0, 0.25, 0.5) if a < edge]
    assert edge - 0.25 / 2**BISECTIONS <= weighed <= edge + 1e-5  # the points move it by 1e-6
    reason = next(g for g in cut.given_up if "and beyond" in g)
    assert "a unit of the next batch printed from it is not a valid design: sensors: S1" in reason
    assert weighed < float(reason.split()[1]) <= weighed + 0.25 / 2**BISECTIONS + 1e-12
    assert cut.step in losses
