"""Coefficient files: the JSON round trip of a fitted model and bad documents."""

import json

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from reflector_opt.calibration._coefficients import (
    load_model,
    model_from_dict,
    model_to_dict,
    save_model,
)
from reflector_opt.calibration._models import Eq5, Eq6, Polynomial
from reflector_opt.util._errors import InputError
from tests.calibration.eq6_data import synthetic


@pytest.mark.parametrize(
    "model", [Eq5(), Eq5(intercept=True), Eq6(loss="huber"), Polynomial(4, loss="minimax")]
)
def test_json_round_trip(tmp_path, model):
    volts, angles = synthetic(300, sigma_deg=0.5)
    model.fit(volts, angles)
    path = tmp_path / "model.json"
    save_model(model, path)
    loaded = load_model(path)
    assert type(loaded) is type(model)
    assert loaded.get_params() == model.get_params()
    assert_allclose(loaded.predict(volts), model.predict(volts), atol=1e-10)
    # The file's raw-voltage numbers are kept as read, not converted to the scaled inputs and
    # back (two changes of basis, which moved poly4's coefficients by ~1e-14 relative).
    assert_array_equal(loaded.coef_, model.coef_)
    assert_array_equal(model_to_dict(loaded)["coefficients"]["roll_deg"], model.coef_[1])
    assert_allclose(loaded.training_rms_deg_, model.training_rms_deg_)
    data = json.loads(path.read_text())
    assert data["coefficients"]["pitch_deg"] == model.coef_[0].tolist()
    assert data["terms"] == model.term_names


def test_model_from_dict_rejects_bad_documents():
    model = Eq6().fit(*synthetic(100))
    good = model_to_dict(model)
    cases = [
        ({k: v for k, v in good.items() if k != "coefficients"}, "coefficients: missing"),
        ({**good, "model": "eq9"}, "unknown model"),
        ({**good, "coefficients": {"pitch_deg": [1.0] * 7, "roll_deg": [1.0] * 8}}, "8 numbers"),
        ({**good, "input_scale_v": [1.0, 0.0]}, r"input_scale_v\[1\]: expected a number > 0"),
        ({**good, "terms": ["v1"] * 8}, "terms"),
        ({**good, "params": {"fit": "lsq", "colour": 1}}, "params"),
        (  # finite numbers whose scaled form overflows (once a RuntimeWarning and inf angles)
            {**good, "coefficients": {"pitch_deg": [1.5e308] * 8, "roll_deg": [1.5e308] * 8}},
            r"coefficients: too large for input_scale_v",
        ),
    ]
    for document, message in cases:
        with pytest.raises(InputError, match=message):
            model_from_dict(document)


def test_load_model_errors(tmp_path):
    with pytest.raises(InputError, match="cannot read"):
        load_model(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{")
    with pytest.raises(InputError, match="not valid JSON"):
        load_model(bad)
    bad.write_text('{"format": "something-else"}')
    with pytest.raises(InputError, match="not a calibration model"):
        load_model(bad)


def test_an_unfitted_model_has_no_document():
    with pytest.raises(InputError, match="not fitted"):
        model_to_dict(Eq6())


def test_eq5_file_must_not_be_centred():
    document = model_to_dict(Eq5().fit(*synthetic(50)))
    with pytest.raises(InputError, match="must be zero for eq5"):
        model_from_dict({**document, "input_centre_v": [1.0, 0.0]})
    assert np.all(model_from_dict(document).centre_v_ == 0.0)
