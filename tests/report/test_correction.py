"""The report's print-correction section."""

from dataclasses import replace

from reflector_opt.report._correction import correction_blocks
from reflector_opt.report._render import render_markdown

CORRECTION = {
    "format": "reflector-opt/correction@1",
    "batch": "B1",
    "sources": [{"file": "a.json", "sha256": "0" * 64, "batch": "B1", "units": ["1", "2"]}],
    "n_units": 2,
    "changed": {
        "reflector_centre_z_mm": {"change": -0.0412, "std": 0.011, "determined_share": 0.9}
    },
    "not_determined": ["sensor 1 tilt towards its detector"],
    "prediction": {
        "without": {
            "worst_resolution_deg": {"mean": 0.1, "max": 0.12},
            "calibration_rms_deg": {"pitch": 0.05, "roll": 0.06},
        },
        "with": {
            "worst_resolution_deg": {"mean": 0.08, "max": 0.09},
            "calibration_rms_deg": {"pitch": 0.04, "roll": 0.05},
        },
        "gain": 1.25,
    },
}


def test_a_design_without_a_correction_has_no_section(design):
    assert correction_blocks(design) == []


def test_the_section_shows_the_change_what_was_left_and_the_prediction(design):
    text = render_markdown(correction_blocks(replace(design, correction=CORRECTION)))
    assert "## Print correction" in text
    assert "2 identified unit(s) of print batch B1 (a.json)" in text
    assert "| reflector_centre_z_mm | -0.0412 | 0.011 |" in text
    assert "sensor 1 tilt towards its detector" in text
    assert "| corrected | 0.08 | 0.09 | 0.04 | 0.05 |" in text
    assert "1.25×" in text


def test_nothing_changed_is_said(design):
    quiet = {**CORRECTION, "changed": {}, "prediction": None}
    text = render_markdown(correction_blocks(replace(design, correction=quiet)))
    assert "Nothing was changed" in text and "next batch" not in text
