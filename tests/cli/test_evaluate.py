"""``reflector-opt evaluate`` prints its run's text: a notebook's ``run.text()`` is what the
command prints, byte for byte."""

from pathlib import Path

import reflector_opt as ro
from reflector_opt.cli import main

SAMPLE = Path(__file__).resolve().parents[2] / "examples" / "data" / "design.json"


def test_evaluate_prints_the_runs_text(capsys):
    assert main(["evaluate", str(SAMPLE), "--no-predict", "--quiet"]) == 0
    printed = capsys.readouterr().out
    run = ro.evaluate(SAMPLE, predict=False)
    assert printed == run.text() + "\n"
    # the sample design's two sensors over its grid of 0.1° steps on ±15°: 301 × 301 poses
    assert printed.startswith("in use in the default conditions (docs/conditions.md) (±2 K, ")
    assert "\nworkspace: 90601 poses\nS1 (NJL5901R-2): d " in printed
    assert "drift sensitivity" in printed and "predicted calibration" not in printed
    assert run._repr_html_().startswith("<pre>in use in the default conditions")
