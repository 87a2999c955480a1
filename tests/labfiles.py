"""A simulated lab's files, shared by the command-line tests: calibration data, coefficients
and a voltage log of two built units of the default design."""

from reflector_opt.calibration._files import write_calibration_csv, write_voltage_log
from reflector_opt.calibration._synthetic import built_units, calibration_data, voltage_log
from reflector_opt.calibration._unit_calibration import calibrate_csv, save_calibrations
from reflector_opt.design import default_design


def write_lab_files(folder):
    """Write ``data.csv``, ``coef.json`` (fitted to it) and ``log.csv`` into ``folder``."""
    design = default_design()
    units = built_units(design, seed=3)[:2]
    data = calibration_data(design, units, step_deg=5.0, seed=1)
    write_calibration_csv(folder / "data.csv", data["unit"], data["volts"], data["angles_deg"])
    save_calibrations(folder / "coef.json", calibrate_csv(folder / "data.csv", folds=0))
    log = voltage_log(design, units, "pitch", cycles=1, samples_per_cycle=6, seed=2)
    write_voltage_log(folder / "log.csv", log["sample"], log["unit"], log["volts"])
