"""estimate's per-sample 1σ (calibration._unit_calibration.angle_sigma) against the spread of
its estimates over noise draws, on readings of the independent truth (tests/independent)."""

import numpy as np
import pytest

from reflector_opt.calibration import Eq6, _unit_calibration
from reflector_opt.calibration._unit_calibration import save_calibrations
from reflector_opt.workflow import estimate
from tests.robot.test_stream import _calibrations
from tests.robot.test_virtual import truth

NOISE_V = 1e-2
DRAWS = 1000
POSES = np.array([[0.0, 0.0], [10.0, -5.0], [-12.0, 8.0], [5.0, 12.0]])


@pytest.fixture(scope="module")
def draws(tmp_path_factory):
    """A log of the three built units at each pose, each reading drawn DRAWS times with 10 mV
    of Gaussian noise; the coefficients of Eq 6 fitted on the noise-free truth."""
    folder = tmp_path_factory.mktemp("sigma")
    calibrations = _calibrations(Eq6)
    save_calibrations(folder / "coef.json", calibrations)
    rng = np.random.default_rng(3)
    clean = np.stack([truth(np.repeat([pose], 3, axis=0), 0) for pose in POSES])  # (P, 3, 2)
    volts = clean[:, None] + rng.normal(0, NOISE_V, (len(POSES), DRAWS, 3, 2))
    with open(folder / "log.csv", "w") as handle:
        handle.write("sample,unit,v1,v2\n")
        for i, (v1, v2) in enumerate(volts.reshape(-1, 2)):
            handle.write(f"{i // 3},{i % 3 + 1},{float(v1)!r},{float(v2)!r}\n")
    error = np.array([c.model.training_rms_deg_ for c in calibrations])  # (3, 2)
    return folder, error


def _estimated(folder):
    out = estimate(folder / "coef.json", folder / "log.csv", noise_v=NOISE_V).write(
        folder / "angles.csv"
    )
    header = out.files[0].read_text().splitlines()[0].split(",")
    data = np.loadtxt(out.files[0], delimiter=",", skiprows=1)
    angles = np.stack(
        [data[:, header.index(f"{u}_{a}_deg")] for u in "123" for a in ("pitch", "roll")], 1
    )
    sigma = np.stack(
        [data[:, header.index(f"{u}_{a}_sigma_deg")] for u in "123" for a in ("pitch", "roll")],
        1,
    )
    shape = (len(POSES), DRAWS, 3, 2)
    return angles.reshape(shape), sigma.reshape(shape)


def _agrees(sigma, angles, error):
    """The mean σ at each pose, unit and angle within 10 % of √(spread² + e²): the spread of the
    estimates over the draws (1000 draws: its standard error ≈ 2.2 %) and the calibration's
    own error e, which the draws cannot show (a bias at each pose)."""
    spread = angles.std(axis=1, ddof=1)  # (P, 3, 2)
    expected = np.sqrt(spread**2 + error**2)
    return np.abs(sigma.mean(axis=1) / expected - 1).max() < 0.10


def test_sigma_is_the_spread_over_noise_draws(draws):
    folder, error = draws
    angles, sigma = _estimated(folder)
    assert (angles.std(axis=1) > 1.5 * error).all()  # the noise dominates: the test sees it
    assert _agrees(sigma, angles, error)
    assert not _agrees(2 * sigma, angles, error)


def test_a_doubled_noise_term_fails_the_comparison(draws, monkeypatch):
    folder, error = draws
    jacobian = _unit_calibration.unit_jacobian
    monkeypatch.setattr(_unit_calibration, "unit_jacobian", lambda *a: 2 * jacobian(*a))
    angles, sigma = _estimated(folder)
    assert not _agrees(sigma, angles, error)
