"""evaluate's text: a warning where the paper's form is far from the floor, and the paper's
percentages said for what they are (issue 37, item 8)."""

import copy

from reflector_opt.tolerance._prediction import CalibrationPrediction
from reflector_opt.workflow._evaluate_text import FAR_FROM_FLOOR, _segment_lines, calibration_lines


def _form(rms, misfit, noise, percent):
    return {
        "rms_deg": dict(zip(("pitch", "roll"), rms, strict=True)),
        "max_deg": {"pitch": 2 * rms[0], "roll": 2 * rms[1]},
        "percent_error": dict(zip(("pitch", "roll"), percent, strict=True)),
        "misfit_rms_deg": dict(zip(("pitch", "roll"), misfit, strict=True)),
        "noise_rms_deg": dict(zip(("pitch", "roll"), noise, strict=True)),
        "n_calibration": 90601,
    }


#: The prediction of `evaluate examples/data/design.json` (the optimised design), rounded.
CALIBRATION = {
    "protocol": {"n_units": 4, "reference_sigma_deg": 0.05, "n_validation": 5000, "step_deg": 0.1},
    "floor_rms_deg": {"pitch": 0.077, "roll": 0.077},
    "eq5": _form((8.606, 0.794), (8.606, 0.791), (0.006, 0.075), (28.69, 2.65)),
    "eq6": _form((0.190, 0.263), (0.173, 0.252), (0.075, 0.074), (0.63, 0.88)),
    "recommended": {
        **_form((0.081, 0.085), (0.015, 0.018), (0.080, 0.083), (0.27, 0.28)),
        "models": ["poly4", "poly5", "poly4", "poly4"],
        "n_calibration": 196,
        "plan": {"pattern": "grid"},
        "floor_ratio": {"pitch": 1.05, "roll": 1.11},
    },
}


def test_eq5_on_the_optimised_design_warns_and_names_the_form_to_use():
    """8.6° RMS is 8.606 / 0.077 = 112 times the floor: the form's misfit, not noise."""
    calibration = CalibrationPrediction.from_dict(CALIBRATION)
    warnings = [line for line in calibration_lines(calibration) if "warning" in line]
    assert warnings == [
        "  warning: eq5 is 112× the floor in pitch (8.606° RMS, 28.7 % of the span; its model "
        "misfit): it cannot follow this design's response; calibrate with poly4/poly5 instead "
        "(`calibrate --model auto`: 0.081° / 0.085° predicted)"
    ]


def test_a_form_near_its_floor_gives_no_warning():
    """eq6 at 0.263 / 0.077 = 3.4 times the floor is not far from it; nor is eq5 there."""
    near = copy.deepcopy(CALIBRATION)
    near["eq5"] = _form((0.5, 0.5), (0.4, 0.4), (0.1, 0.1), (1.7, 1.7))  # 6.5x
    assert 0.5 / 0.077 < FAR_FROM_FLOOR < 8.606 / 0.077
    near = CalibrationPrediction.from_dict(near)
    assert not [line for line in calibration_lines(near) if "warning" in line]


def test_the_papers_percentages_say_what_they_are():
    """'(paper 0.77 %, undefined there)' left the reader to guess what was undefined."""
    segment = {
        "n_units": 4,
        "model": "eq6",
        "pitch": {
            "amplitude_deg": 60.0,
            "predicted": {
                "rms_deg": 0.70,
                "max_deg": 1.37,
                "percent_error": 0.58,
                "position_rms_mm": 0.56,
            },
            "paper": {"rms_deg": 2.45, "max_deg": 6.03, "percent_error": 0.77},
        },
        "roll": {
            "amplitude_deg": 60.0,
            "predicted": {
                "rms_deg": 1.01,
                "max_deg": 1.86,
                "percent_error": 0.84,
                "position_rms_mm": 0.81,
            },
            "paper": {"rms_deg": 3.27, "max_deg": 6.86, "percent_error": 0.21},
        },
    }
    text = "\n".join(_segment_lines(segment))
    assert "undefined there" not in text
    assert "% = RMS / the tip angle's span" in text and "it does not say what it is" in text
    assert "(paper 0.77 %, base not stated)" in text
