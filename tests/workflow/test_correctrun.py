"""The run of ``correct`` (reflector_opt/workflow/_correctrun.py), built from a hand-made batch
mean and correction: frozen, a JSON summary that holds what the fields hold, and the text,
``repr`` and notebook display of the figures given, worked out by hand.

The batch: two geometry parameters (the sphere centre's z, prior std 0.1 mm; sensor 1's
tilt, 1°), two determined directions, one along each — the centre at +3.0 ± 0.5 prior stds
(t = 6, shrinkage factor 1 − (2/6)² = 8/9), the tilt at +0.4 ± 0.5 (t = 0.8, factor 0) —
and seven left undetermined. At step 0.5 the centre changes by −0.5 · 8/9 · 3.0 · 0.1 mm =
−0.1333 mm, with std 0.5 · 8/9 · 0.5 · 0.1 mm = 0.0222 mm.
"""

import dataclasses
import html
import json
from pathlib import Path

import numpy as np
import pytest

from reflector_opt.asbuilt._batch import Batch, Source
from reflector_opt.asbuilt._correction import Correction
from reflector_opt.asbuilt._pooling import BatchMean, Direction
from reflector_opt.workflow._correctrun import CorrectRun

NAMES = ("reflector_centre_z_mm", "sensor_1_tilt_deg")
PRIOR_STD = np.array([0.1, 1.0])
CENTRE = Direction("reflector centre z", np.array([1.0, 0.0]), 3.0, 0.5, 0.3)
TILT = Direction("sensor 1 tilt", np.array([0.0, 1.0]), 0.4, 0.5, 0.4)
UNDETERMINED = tuple(
    Direction(f"u{k}", np.array([0.0, 1.0]), float("nan"), float("inf"), 0.9) for k in range(1, 8)
)

#: The predicted next batch's figures (:func:`reflector_opt.asbuilt._userloss.batch_figures`).
FIGURES = {
    "without": {
        "angle_deg": {"mean": 0.1, "max": 0.12},
        "drift_deg": {"mean": 0.02, "max": 0.03},
        "window_mm": [0.05, -0.02],
        "peak_mm": [0.1, 0.08],
        "clearance_mm": 0.4,
    },
    "with": {
        "angle_deg": {"mean": 0.09, "max": 0.11},
        "drift_deg": {"mean": 0.015, "max": 0.02},
        "window_mm": [0.06, 0.03],
        "peak_mm": [0.11, 0.09],
        "clearance_mm": 0.38,
    },
}

#: :func:`reflector_opt.asbuilt._batchforecast.predict_next_batch`'s shape.
PREDICTION = {
    "without": {
        "worst_resolution_deg": {"mean": 0.1, "max": 0.12},
        "calibration_rms_deg": {"pitch": 0.05, "roll": 0.06},
    },
    "with": {
        "worst_resolution_deg": {"mean": 0.08, "max": 0.1},
        "calibration_rms_deg": {"pitch": 0.04, "roll": 0.05},
    },
    "gain": 1.25,
}

FILES = [Path("out/design.json"), Path("out/cad_report.json")]


def _batch(n_units=3, name="B1"):
    deviations = np.array([[0.30, 0.5], [0.35, 0.3], [0.25, 0.4]])[:n_units]
    labels = tuple(f"unit {k}" for k in range(1, n_units + 1))
    return Batch(
        design=None,
        names=NAMES,
        prior_std=PRIOR_STD,
        labels=labels,
        deviations=deviations,
        covariances=np.tile(np.diag([0.01, 0.25]), (n_units, 1, 1)),
        blocks=deviations,
        surfaces=np.zeros((n_units, 2)),
        sources=(Source("a.json", "0" * 64, name, labels),),
        batch=name,
    )


def _mean(batch=None, directions=(CENTRE, TILT), undetermined=UNDETERMINED, **fields):
    values = {"scatter_factor": 0.8, "scatter_estimated": True, "assume_systematic": False}
    return BatchMean(
        batch=batch or _batch(),
        directions=directions,
        undetermined=undetermined,
        mean=np.array([0.3, 0.4]),
        mean_std=np.array([0.05, 0.5]),
        **(values | fields),
    )


def _correction(
    mean, step=0.5, resolved=(True, True), given_up=("sensor 2's peak < 0.1 mm",), threshold=5.991
):
    return Correction(
        mean=mean,
        factors=(8 / 9, 0.0),
        chi2=36.64,
        threshold=threshold,
        level=2.0,
        confidence=0.95,
        resolved=resolved,
        step=step,
        given_up=given_up,
    )


def _run(mean=None, correction=None, prediction=PREDICTION):
    mean = mean or _mean()
    return CorrectRun(
        mean=mean,
        correction=correction or _correction(mean),
        design=None,
        prediction=prediction,
        losses={0.0: 0.1, 0.5: 0.08, 1.0: 0.09},
        figures=FIGURES,
        parts=None,
        cad={"report": "cad_report.json", "files": {}},
        out=Path("out"),
        files=FILES,
    )


def _json(summary):
    """The summary through strict JSON and back (no NaN, no infinity, no objects)."""
    return json.loads(json.dumps(summary, allow_nan=False))


def test_with_no_direction_resolved_the_summary_is_still_strict_json():
    """No resolved direction leaves no χ² test: its threshold is infinite, written as null."""
    mean = _mean()
    run = _run(mean, _correction(mean, resolved=(False, False), threshold=float("inf")))
    assert _json(run.to_dict())["correction"]["test"]["threshold"] is None


def test_a_correct_run_cannot_be_reassigned():
    run = _run()
    for field in dataclasses.fields(run):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(run, field.name, None)


def test_the_summary_holds_the_batch_the_correction_the_losses_and_the_files():
    run = _run()
    summary = _json(run.to_dict())
    assert summary == {
        "batch": _json(run.mean.to_dict()),
        "correction": _json(run.correction.to_dict()),
        "expected_loss_deg": {"0": 0.1, "0.5": 0.08, "1": 0.09},
        "figures": FIGURES,
        "prediction": PREDICTION,
        "cad": run.cad,
        "files": [str(p) for p in FILES],
    }
    assert summary["batch"]["n_units"] == 3 and summary["correction"]["step"] == 0.5
    assert summary["correction"]["changed"]["reflector_centre_z_mm"]["change"] == pytest.approx(
        -0.5 * 8 / 9 * 3.0 * 0.1
    )


def test_the_text_says_the_batch_each_direction_the_step_the_changes_and_the_gain():
    assert _run().text().splitlines() == [
        "batch 'B1': 3 unit(s) from 1 file(s); unit-to-unit scatter 0.80× the tolerance "
        "model's (estimated, prior scale 1)",
        "determined combinations: batch mean ± std, in tolerance-spread units",
        "  reflector centre z: +3.00 ± 0.50 (t +6.0, corrected by 0.44)",
        "  sensor 1 tilt: +0.40 ± 0.50 (t +0.8, left)",
        "rule: each resolved combination by max(0, 1 − (2/t)²), times the step 0.5 (least "
        "expected loss, predicted print printable)",
        "  given up: sensor 2's peak < 0.1 mm",
        "changes to the drawing (± std; below 0.5 µm and 0.005° not listed):",
        "  reflector_centre_z_mm           -0.1333 mm ± 0.0222 mm",
        "left as drawn, not determined by the data:",
        "  u1",
        "  u2",
        "  u3",
        "  u4",
        "  u5",
        "  and 2 more (--json lists them)",
        "next batch, predicted (fast model): without → with the correction",
        "  worst-case resolution, mean over units: 0.1000° → 0.0900°; drift per 1 % light: "
        "0.0200° → 0.0150°",
        "  smallest margins, µm: window 50/-20 → 60/30; peak 100/80 → 110/90; clearance 400 → 380",
        "next batch, predicted (fast model, this batch's deviations printed again):",
        "  worst-case resolution, mean over units: 0.1000° without, 0.0800° with the "
        "correction (gain 1.250×)",
        "  calibration RMS (pitch, roll): 0.0500°, 0.0600° without; 0.0400°, 0.0500° with",
    ]


def test_two_units_taken_as_systematic_with_model_form_and_reference_say_so():
    form = dataclasses.replace(CENTRE, model_form=0.3, reference=0.2)
    mean = _mean(
        _batch(n_units=2, name=None),
        directions=(form, TILT),
        scatter_factor=0.0,
        scatter_estimated=False,
        assume_systematic=True,
        model_form=("AS_BUILT.json",),
    )
    lines = _run(mean).text().splitlines()
    assert lines[:5] == [
        "batch (no name recorded): 2 unit(s) from 1 file(s); unit-to-unit scatter 0.00× the "
        "tolerance model's (assumed: none, --assume-systematic)",
        "  the identification's model-form bias is weighed as an uncertainty (AS_BUILT.json)",
        "  note: fewer than 3 units cannot tell systematic from random; their deviation is "
        "taken as systematic",
        "determined combinations: batch mean ± std, in tolerance-spread units",
        "  reflector centre z: +3.00 ± 0.50 (t +6.0, model form ± 0.30, angle reference ± "
        "0.20, corrected by 0.44)",
    ]
    assumed = _run(_mean(scatter_factor=1.0, scatter_estimated=False)).text().splitlines()[0]
    assert assumed.endswith("unit-to-unit scatter 1.00× the tolerance model's (assumed)")


def test_nothing_changed_nothing_left_open_and_no_prediction():
    mean = _mean(undetermined=())
    correction = _correction(mean, step=0.0, resolved=(True, False), given_up=())
    lines = _run(mean, correction, prediction=None).text().splitlines()
    assert lines[2:6] == [
        "  reflector centre z: +3.00 ± 0.50 (t +6.0, left)",
        "  sensor 1 tilt: +0.40 ± 0.50 (t +0.8, left, std > tolerance)",
        "rule: each resolved combination by max(0, 1 − (2/t)²), times the step 0 (least "
        "expected loss, predicted print printable)",
        "changes to the drawing: none (the design is unchanged)",
    ]
    assert lines[6] == "next batch, predicted (fast model): without → with the correction"
    assert len(lines) == 9  # the figures' three lines end it


def test_each_change_in_its_unit_and_a_change_too_small_to_list_still_a_change():
    """Along centre z + tilt (weights 0.6, 0.8) at t = 6 and step 1: the change is
    −8/9 · 3.0 · (0.6 · 0.1 mm, 0.8 · 1°) = (−0.1600 mm, −2.1333°), std 8/9 · 0.5 · (0.06 mm,
    0.8°) = (0.0267 mm, 0.3556°). At step 0.001 the centre moves 0.16 µm and the tilt 0.0021°,
    below what is listed: the drawing still changes."""
    both = Direction("reflector centre z + sensor 1 tilt", np.array([0.6, 0.8]), 3.0, 0.5, 0.3)
    mean = _mean(directions=(both,), undetermined=())
    correction = dataclasses.replace(
        _correction(mean, step=1.0), factors=(8 / 9,), resolved=(True,)
    )
    lines = _run(mean, correction).text().splitlines()
    start = lines.index("changes to the drawing (± std; below 0.5 µm and 0.005° not listed):")
    assert lines[start + 1 : start + 3] == [
        "  reflector_centre_z_mm           -0.1600 mm ± 0.0267 mm",
        "  sensor_1_tilt_deg               -2.1333° ± 0.3556°",
    ]
    small = _run(mean, correction.with_step(0.001)).text().splitlines()
    start = small.index("changes to the drawing (± std; below 0.5 µm and 0.005° not listed):")
    assert small[start + 1] == "next batch, predicted (fast model): without → with the correction"


def test_a_prediction_without_sensitivity_or_calibration_says_so():
    without = {"worst_resolution_deg": {"mean": None, "max": None}}
    corrected = {"worst_resolution_deg": {"mean": 0.08, "max": 0.1}}
    prediction = {"without": without, "with": corrected, "gain": None}
    assert _run(prediction=prediction).text().splitlines()[-1] == (
        "  worst-case resolution, mean over units: no sensitivity without, 0.0800° with the "
        "correction (gain n/a)"
    )


def test_the_repr_and_the_notebook_display_are_the_text():
    run = _run()
    assert repr(run) == run.text()
    assert run._repr_html_() == f"<pre>{html.escape(run.text())}</pre>"
    assert "sensor 2&#x27;s peak &lt; 0.1 mm" in run._repr_html_()
