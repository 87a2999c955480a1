"""The example scripts run and show what their docs say."""

import runpy
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_fig5_linear_calibration(tmp_path):
    out = tmp_path / "fig5.png"
    example = runpy.run_path(str(EXAMPLES / "fig5_linear_calibration.py"), run_name="example")
    rms = example["run"](out)
    # relative intensities follow the motion (the paper's finding); raw ones mix the axes
    assert max(rms["relative"]) < 5.0
    assert min(rms["raw"]) > max(rms["relative"])
    assert out.stat().st_size > 10_000
