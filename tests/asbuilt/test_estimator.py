"""An identified unit's calibration (asbuilt.estimator): its forward model inverted, in its
reference's frame, and the units of an AS_BUILT.json as calibrations. The estimator contract
all calibration models keep is tested in tests/calibration/test_estimator_contract.py."""

import numpy as np
import pytest

from reflector_opt.asbuilt._asbuiltfile import save_as_built
from reflector_opt.asbuilt._estimator import AsBuiltModel, load_unit_calibrations, reference_of
from reflector_opt.asbuilt._parameters import REFERENCE_NAMES
from reflector_opt.model._forward import voltages
from reflector_opt.model._noise import Mismatch
from reflector_opt.util._errors import InputError
from tests.asbuilt.printloop import printed

POSES = np.array([[5.0, -3.0], [-12.0, 10.0], [0.0, 0.0]])
MISMATCH = Mismatch((1.03, 0.97), (0.02, -0.01))


def test_the_inverse_of_the_units_own_voltages_is_the_pose(design):
    volts = MISMATCH.apply(voltages(design, POSES[:, 0], POSES[:, 1]))
    model = AsBuiltModel(design, MISMATCH)
    with pytest.raises(InputError, match="not fitted"):
        model.predict(volts)
    np.testing.assert_allclose(model.fit().predict(volts), POSES, atol=1e-4)
    # A reference that reads pitch 1° high and roll 0.5° low (no twist): the same voltages
    # are the poses it reads, (γ + 1, α − 0.5).
    offset = AsBuiltModel(design, MISMATCH, reference_deg=(1.0, -0.5, 0.0)).fit()
    np.testing.assert_allclose(offset.predict(volts), POSES + np.array([1.0, -0.5]), atol=1e-4)


def test_reference_of_a_units_rows():
    assert reference_of(None) == reference_of({}) == (0.0, 0.0, 0.0)
    rows = {
        name: {"estimate": value} for name, value in zip(REFERENCE_NAMES, (0.5, -1, 2), strict=True)
    }
    assert reference_of(rows) == (0.5, -1.0, 2.0)


def test_the_units_of_a_file_are_their_identified_calibrations(tmp_path):
    _, result = printed("strong")
    path = tmp_path / "AS_BUILT.json"
    save_as_built(result, path)
    calibrations = load_unit_calibrations(path)
    assert [c.unit for c in calibrations] == ["1", "2", "3", "4"]
    for u in (0, 3):
        built, mismatch = result.as_built(u)
        model = calibrations[u].model
        assert isinstance(model, AsBuiltModel)
        assert model.reference_deg == (0.0, 0.0, 0.0)  # identified with an exact reference
        volts = model.volts(POSES[:, 0], POSES[:, 1])
        np.testing.assert_allclose(model.predict(volts), POSES, atol=1e-3)
        np.testing.assert_allclose(model.mismatch.gain, mismatch.gain, rtol=1e-12)
        assert model.design.reflector.radius_mm == pytest.approx(built.reflector.radius_mm)
