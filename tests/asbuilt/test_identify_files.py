"""Identification from the lab's files with flat-target curves: the sample data's unit 1, its
surface against truth.json, the surface reported inside its range."""

import json
from pathlib import Path

import numpy as np
import pytest

from reflector_opt.asbuilt._identification import identify
from reflector_opt.asbuilt._identify_files import read_curves
from reflector_opt.calibration._files import read_calibration_csv
from reflector_opt.design import load_design

SAMPLE = Path(__file__).parents[2] / "examples" / "data"
TRUTH = json.loads((SAMPLE / "truth.json").read_text())["units"][0]


@pytest.fixture(scope="module")
def unit_1():
    """Unit 1 of the sample data with both sensors' curves, identified as ``identify`` does
    (the spread and the model-form amplitudes fitted)."""
    design = load_design(SAMPLE / "design.json")
    samples = read_calibration_csv(SAMPLE / "data.csv")
    curves = read_curves(design, [f"1:S{k}={SAMPLE}/s{k}.csv" for k in (1, 2)], ["1"])
    return identify(design, {"1": samples["1"]}, curves=curves, profiles=False)


@pytest.mark.slow
def test_the_coupons_reflectance_is_found_within_its_interval(unit_1):
    row = unit_1.shared_parameters()["reflectance"]
    assert abs(row["estimate"] - TRUTH["reflectance"]) < 0.03
    assert abs(row["estimate"] - TRUTH["reflectance"]) < 1.645 * row["std"]
    assert row["identifiable"]


@pytest.mark.slow
def test_the_surface_is_reported_as_the_model_used_it(unit_1):
    """ρ, f and the spread ℓ are reported as the model used them, each within its range."""
    rows = unit_1.shared_parameters()
    raw = unit_1.layout.nominal()[:3] + unit_1.x[:3]
    for (name, row), value, (low, high) in zip(
        rows.items(), raw, [(1e-3, 1.0), (0.0, 1.0), (0.0, 1.0)], strict=True
    ):
        assert low <= row["estimate"] <= high, name
        assert row["estimate"] == pytest.approx(float(np.clip(value, low, high)), abs=0.0)


@pytest.mark.slow
def test_no_std_exceeds_its_prior(unit_1):
    assert np.all(unit_1.std <= unit_1.layout.prior_std() * (1 + 1e-9))
