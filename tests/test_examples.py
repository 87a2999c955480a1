"""The example scripts run and show what their docs say."""

import runpy
from pathlib import Path

import numpy as np

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_fig5_linear_calibration(tmp_path):
    out = tmp_path / "fig5.png"
    example = runpy.run_path(str(EXAMPLES / "fig5_linear_calibration.py"), run_name="example")
    rms = example["run"](out)
    # relative intensities follow the motion (the paper's finding); raw ones mix the axes
    assert max(rms["relative"]) < 5.0
    assert min(rms["raw"]) > max(rms["relative"])
    assert out.stat().st_size > 10_000


def test_calibration_tables_are_consistent():
    """The script behind docs/calibration.md's figures, on a 1° grid (961 calibration poses)."""
    tables = runpy.run_path(str(EXAMPLES / "calibration_tables.py"), run_name="example")
    results = tables["compute"](step_deg=1.0)
    models = results["models"]
    eq6, minimax = models["eq6"], models["eq6, minimax"]
    # the full quartic contains Eq 6's terms and more: it must fit the smooth response better
    assert np.all(models["poly4"].total.rms_deg < eq6.total.rms_deg)
    # minimax minimises the largest calibration residual, so it cannot exceed least squares'
    assert np.all(minimax.model.training_max_deg_ <= eq6.model.training_max_deg_ + 1e-6)
    # and the better unit calibration gives the smaller tip error in both segment motions
    for axis in ("pitch", "roll"):
        segment = {key: results["segment"][key][axis]["predicted"] for key in ("eq6", "poly4")}
        assert segment["poly4"]["rms_deg"] < segment["eq6"]["rms_deg"]


def test_model_vs_raytrace_agrees_and_labels_its_buckets():
    """The fast model against the exact reference and the ray count, on a few geometries."""
    example = runpy.run_path(str(EXAMPLES / "model_vs_raytrace.py"), run_name="example")
    rows = example["compare"](rays=40_000, radii=(9.0,), tilts=(-10, 0, 15), distances=(1.0,))
    assert {r["surface"] for r in rows} == {"mirror", "lambertian"}
    for r in rows:
        assert abs(r["fast"] / r["exact"] - 1.0) < 0.005
        assert abs(r["traced"] - r["exact"]) < 4.0 * r["sigma"]
    summary = example["summarise"](rows)
    # each bucket holds exactly the tilts its label names
    assert {s["bucket"]: s["cases"] for s in summary if s["surface"] == "mirror"} == {
        "|i| ≤ 5°": 2,
        "5° < |i| ≤ 10°": 2,
        "10° < |i| ≤ 15°": 2,
    }
