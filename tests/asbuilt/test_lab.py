"""Identification from the lab's files with flat-target curves: the sample data's unit 1, its
surface against truth.json, the surface reported inside its range, a std above its prior said."""

import json
from pathlib import Path

import numpy as np
import pytest

from reflector_opt.asbuilt.identification import identify
from reflector_opt.asbuilt.lab import read_curves
from reflector_opt.calibration.files import read_calibration_csv
from reflector_opt.cli.identify import _above_prior_lines
from reflector_opt.design import load_design

SAMPLE = Path(__file__).parents[2] / "examples" / "data"
TRUTH = json.loads((SAMPLE / "truth.json").read_text())["units"][0]


@pytest.fixture(scope="module")
def unit_1():
    """Unit 1 of the sample data with both sensors' curves (statistical covariance only:
    the model-form term takes 40 s more; its effect on the std is tested below by hand)."""
    design = load_design(SAMPLE / "design.json")
    samples = read_calibration_csv(SAMPLE / "data.csv")
    curves = read_curves(design, [f"1:S{k}={SAMPLE}/s{k}.csv" for k in (1, 2)], ["1"])
    return identify(design, {"1": samples["1"]}, curves=curves, model_form=None, profiles=False)


def test_the_coupons_reflectance_is_found_within_its_interval(unit_1):
    row = unit_1.shared_parameters()["reflectance"]
    assert abs(row["estimate"] - TRUTH["reflectance"]) < 0.03
    assert abs(row["estimate"] - TRUTH["reflectance"]) < 1.645 * row["std"]
    assert row["identifiable"]


def test_the_surface_is_reported_as_the_model_used_it(unit_1):
    """The fit's specular fraction ends at its bound 0 (the curves' near field, shaped by
    the resin's spread and the LED, reads as less mirror than none): reported as the clipped
    value the model used, never below 0."""
    rows = unit_1.shared_parameters()
    raw = unit_1.layout.nominal()[:2] + unit_1.x[:2]
    for (name, row), value, (low, high) in zip(
        rows.items(), raw, [(1e-3, 1.0), (0.0, 1.0)], strict=True
    ):
        assert low <= row["estimate"] <= high, name
        assert row["estimate"] == pytest.approx(float(np.clip(value, low, high)), abs=0.0)
    assert rows["specular_fraction"]["estimate"] < 0.01


def test_a_std_above_its_prior_is_put_down_to_the_model_form_term():
    rows = {
        "sensor_1_source_radius_mm": {"std": 0.107, "prior_std": 0.03, "model_form_std": 0.107},
        "sensor_1_gain": {"std": 0.002, "prior_std": 0.02, "model_form_std": 0.0003},
    }
    (line,) = _above_prior_lines(rows)
    assert "by the model-form term" in line and "sensor_1_source_radius_mm ± 0.11" in line
    assert "(prior ± 0.03, model form ± 0.11)" in line and "gain" not in line
    assert _above_prior_lines({"gain": rows["sensor_1_gain"]}) == []
