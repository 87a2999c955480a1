"""The next batch predicted from an identified one, with and without a correction."""

import numpy as np
import pytest

from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.asbuilt._batch import Batch
from reflector_opt.asbuilt._batchforecast import (
    predict_next_batch,
    predicted_units,
    workspace_resolution,
)
from reflector_opt.model._forward import respond
from reflector_opt.util._errors import InputError
from tests.asbuilt.printloop import drawn_design, printed


def test_the_resolution_over_the_workspace_is_the_metrics_worst_case():
    design = drawn_design()
    found = workspace_resolution(lambda p, r: respond(design, p, r).volts, design, 1.0)
    metrics = evaluate_metrics(design, 1.0)
    assert found["worst_deg"]["pitch"] == pytest.approx(metrics.worst_pitch_deg, rel=1e-6)
    assert found["worst_deg"]["roll"] == pytest.approx(metrics.worst_roll_deg, rel=1e-6)
    assert found["worst"] == pytest.approx(metrics.worst_resolution_deg, rel=1e-6)
    with pytest.raises(InputError, match="step_deg"):
        workspace_resolution(lambda p, r: respond(design, p, r).volts, design, 0.0)


def test_the_units_printed_again_on_their_own_design_are_the_identified_ones():
    _, result = printed("strong")
    batch = Batch.from_identification(result)
    for u, (built, mismatch) in enumerate(predicted_units(batch, batch.design)):
        expected, expected_mismatch = result.as_built(u)
        assert built.positions_mm == pytest.approx(expected.positions_mm, abs=1e-9)
        assert built.reflector.radius_mm == pytest.approx(expected.reflector.radius_mm)
        assert np.allclose(mismatch.gain, expected_mismatch.gain)


def test_no_correction_predicts_no_gain():
    _, result = printed("strong")
    batch = Batch.from_identification(result)
    prediction = predict_next_batch(batch, batch.design, calibration=False, step_deg=1.5)
    assert prediction["gain"] == pytest.approx(1.0)
    assert prediction["without"] == prediction["with"]
    assert len(prediction["with"]["units"]) == batch.n_units
    assert "calibration_rms_deg" not in prediction["with"]
