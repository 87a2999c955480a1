"""A unit the truth builds, calibrated and read through the CLI's files, against the budget.

The truth (``tests/independent/inuse.py``) makes the calibration data of a unit of the sample
design with VCNT2020 parts (published temperature curves) as the CSV ``calibrate`` reads, on
a 21 × 21 grid over ±15° (1.5° apart) at the calibration's conditions; ``reflector-opt
calibrate`` fits it (poly6, files in tmp_path); the truth then logs the unit at the budget's
7 × 7 poses (5° apart, most between the calibration's nodes) at calibration and in changed
conditions — the junctions 5 K warmer, the supply 10 mV higher — and ``reflector-opt
estimate`` reads the logs. The estimated angles less the truth's true ones are held, pose by
pose and signed, against the budget's scenario for that change, computed from the same design
file.

The tolerance: the estimate's error is the calibration's own floor e0 (the fitted form's
misfit, measured by the log at calibration conditions) plus the change's error. The truth with
a perfect calibration holds each term within 25 % (tests/analysis/test_budget_against_truth.py,
gaps of 2-13 %); the floor adds at most rms(e0) / rms(term) to the relative RMS gap (the
triangle inequality), so the check is 25 % + that ratio, and the same check fails with the
budget's term doubled or of the wrong sign. The fitted form differs from a perfect inverse by
its misfit's slope as well: that is inside the same 25 %.
"""

import csv
import dataclasses
import logging
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from reflector_opt.analysis._budget import error_budget
from reflector_opt.design._conditions import Conditions
from reflector_opt.design._design import load_design
from tests.analysis.test_budget_against_truth import TOLERANCE, gap
from tests.independent.inuse import InUse, readings

ROOT = Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "examples" / "data" / "design.json"
CHANGES = {
    "temperature": (
        Conditions.quiet().replace(temperature_range_k=5.0),
        InUse(delta_t_k=5.0),
    ),
    "supply": (
        Conditions.quiet().replace(supply_change_mv=10.0),
        InUse(supply_change_v=0.010),
    ),
}


def _cli(*args):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, "-m", "reflector_opt", *map(str, args), "-q"],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr


def _write(path, header, rows):
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(header)
        writer.writerows(rows)


def _estimated(tmp_path, coefficients, design, poses, state, name):
    """``estimate``'s angles of the truth's log at ``poses`` in ``state``, (P, 2)."""
    volts = readings(design, poses[:, 0], poses[:, 1], state)
    log = tmp_path / f"{name}.csv"
    _write(
        log,
        ("sample", "unit", "v1", "v2"),
        [(i, 1, *map("{:.9f}".format, v)) for i, v in enumerate(volts)],
    )
    out = tmp_path / f"{name}_angles.csv"
    _cli("estimate", coefficients, log, "-o", out)
    table = np.genfromtxt(out, delimiter=",", names=True)
    return np.stack([table["1_pitch_deg"], table["1_roll_deg"]], axis=-1)


@pytest.mark.slow
def test_a_built_unit_calibrated_and_read_through_the_cli_meets_the_budget(tmp_path):
    logging.disable(logging.WARNING)  # the GE 6 E's rated tilt, once per design
    try:
        sample = load_design(SAMPLE)
    finally:
        logging.disable(logging.NOTSET)
    vcnt = sample.replace(
        sensors=tuple(dataclasses.replace(s, model="VCNT2020") for s in sample.sensors)
    )
    design_file = tmp_path / "design.json"
    vcnt.save(design_file)
    design = load_design(design_file)  # the truth's unit and the budget's, the same file
    nodes = np.linspace(-15.0, 15.0, 21)
    grid = np.stack(np.meshgrid(nodes, nodes, indexing="ij"), axis=-1).reshape(-1, 2)
    volts = readings(design, grid[:, 0], grid[:, 1])
    data = tmp_path / "calibration.csv"
    rows = [
        (1, *map("{:.9f}".format, v), *map("{:.9f}".format, a))
        for v, a in zip(volts, grid, strict=True)
    ]
    _write(data, ("unit", "v1", "v2", "pitch_deg", "roll_deg"), rows)
    coefficients = tmp_path / "unit.json"
    _cli("calibrate", data, "--model", "poly6", "--folds", "0", "-o", coefficients)

    first = error_budget(design, CHANGES["supply"][0], step_deg=5.0)
    poses = np.stack([first.pitch_deg.ravel(), first.roll_deg.ravel()], axis=-1)
    floor = _estimated(tmp_path, coefficients, design, poses, InUse(), "bench") - poses
    assert np.sqrt(np.mean(floor**2)) < 0.02  # the form's misfit, well under the terms
    for name, (conditions, state) in CHANGES.items():
        predicted = error_budget(design, conditions, step_deg=5.0).scenarios[name][0]
        error = _estimated(tmp_path, coefficients, design, poses, state, name) - poses
        allowed = TOLERANCE + np.sqrt(np.mean(floor**2) / np.mean(predicted**2))
        assert gap(predicted, error) < allowed, (name, gap(predicted, error), allowed)
        assert gap(2.0 * predicted, error) > allowed, name
        assert gap(-predicted, error) > allowed, name
