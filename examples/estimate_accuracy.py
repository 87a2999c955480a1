"""How close ``estimate``'s angles come to the true poses of the sample log.

``examples/data/log_truth.csv`` holds the poses ``examples/data/log.csv`` was recorded at
(written by ``examples/make_sample_data.py``), in the columns ``reflector-opt estimate``
writes. This script reads both tables and prints, per quantity, the RMS and the largest
absolute error of the estimate (estimate − truth; degrees for the angles, mm for the tip's
position) over the units, and for the tip::

    reflector-opt calibrate examples/data/data.csv --model auto -o cad_out/coefficients.json
    reflector-opt estimate cad_out/coefficients.json examples/data/log.csv -o cad_out/angles.csv
    python examples/estimate_accuracy.py cad_out/angles.csv [examples/data/log_truth.csv]

docs/calibration.md quotes its output; tests/test_examples.py checks the quote.
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

import numpy as np

TRUTH = Path(__file__).resolve().parent / "data" / "log_truth.csv"


def _table(path):
    with open(path, newline="") as handle:
        rows = list(csv.DictReader(handle))
    return {name: np.array([float(r[name]) for r in rows]) for name in rows[0]}


def accuracy(estimated_csv, truth_csv=TRUTH):
    """RMS and largest absolute error of each quantity of an ``estimate`` output.

    Parameters
    ----------
    estimated_csv : str or pathlib.Path
        The angles ``reflector-opt estimate`` wrote for ``examples/data/log.csv``.
    truth_csv : str or pathlib.Path
        The true poses (default ``examples/data/log_truth.csv``).

    Returns
    -------
    dict
        ``units`` (pitch and roll over every unit and sample), ``tip_angles`` (the tip's
        pitch and roll) and ``tip_position`` (its distance from the true point, mm), each
        ``{"rms": …, "max": …}``, and ``samples``.
    """
    estimated, truth = _table(estimated_csv), _table(truth_csv)
    if not np.array_equal(estimated["sample"], truth["sample"]):
        raise ValueError(f"{estimated_csv}: its samples are not those of {truth_csv}")
    unit = [c for c in truth if c.endswith(("_pitch_deg", "_roll_deg")) and c[0].isdigit()]
    groups = {
        "units": np.concatenate([estimated[c] - truth[c] for c in unit]),
        "tip_angles": np.concatenate(
            [estimated[c] - truth[c] for c in ("tip_pitch_deg", "tip_roll_deg")]
        ),
        "tip_position": np.sqrt(
            sum((estimated[f"tip_{a}_mm"] - truth[f"tip_{a}_mm"]) ** 2 for a in "xyz")
        ),
    }
    result = {
        name: {"rms": float(np.sqrt(np.mean(e**2))), "max": float(np.max(np.abs(e)))}
        for name, e in groups.items()
    }
    return {**result, "samples": int(truth["sample"].size)}


def main(argv):
    """Print the accuracy of ``argv[0]`` against ``argv[1]`` (default the sample's truth)."""
    found = accuracy(*argv[:2])
    print(f"{found['samples']} samples of the sample log, estimate − truth:")
    for name, unit in (("units", "°"), ("tip_angles", "°"), ("tip_position", " mm")):
        e = found[name]
        print(f"  {name.replace('_', ' ')}: RMS {e['rms']:.3f}{unit}, max {e['max']:.3f}{unit}")


if __name__ == "__main__":
    main(sys.argv[1:])
