"""A ranked row of the sensor choice, shared by the tests of the choice and of its report."""


def ranked_row(name, objective, calibration, margin=0.1, radius=11.0):
    """A catalogue part's ranked row: its resolution (deg), calibration errors (deg) and fit."""
    return {
        "part": name,
        "maker": "m",
        "package_mm": [1.0, 1.4, 0.6],
        "status": "ranked",
        "objective_deg": objective,
        "worst_pitch_deg": objective,
        "worst_roll_deg": objective,
        "calibration_rms_deg": calibration,
        "margin_mm": margin,
        "body_radius_mm": radius,
    }
