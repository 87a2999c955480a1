"""How far to correct (asbuilt.stepsearch): the cubature points of the batch mean's
uncertainty, the part the process is predicted to print and the constraint it breaks.

The batch means here are stand-ins holding what these functions read (the names, prior
stds, posterior mean and determined directions of a pooling.BatchMean); choose_step on a
real batch is tested in test_correction.py."""

from types import SimpleNamespace

import numpy as np
import pytest

from reflector_opt.asbuilt.batch import geometry_names
from reflector_opt.asbuilt.stepsearch import posterior_points, predicted_print, print_problem
from reflector_opt.design import default_design
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
    problem = print_problem(default_design(), _mean())  # the default's shell is 0.751 mm
    assert (
        problem
        == "reflector: the reflecting shell is 0.751 mm thick, below the printable minimum 0.8 mm"
    )
    # A print that moves the drawn centre down to the default's thins the shell the same way.
    change = np.zeros(len(NAMES))
    change[NAMES.index("reflector_centre_z_mm")] = -0.3
    assert print_problem(drawn_design(), _mean(change)) == problem
