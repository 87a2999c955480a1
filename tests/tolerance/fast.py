"""Settings that make a unit's evaluation quick: a 2° calibration grid, 300 validation poses."""

from reflector_opt.tolerance import Settings

#: Settings of a quick evaluation: a 2° calibration grid, 300 validation poses, 2° metrics.
FAST = Settings(calibration_step_deg=2.0, n_validation=300, metrics_step_deg=2.0)
