"""Synthetic lab data of built units (calibration.synthetic): the units, their calibration data
and a voltage log."""

import numpy as np
from numpy.testing import assert_allclose

import reflector_opt as ro
from reflector_opt.calibration._synthetic import built_units, calibration_data, voltage_log


def test_synthetic_lab_data_shapes_and_units_differ():
    design = ro.default_design()
    units = built_units(design, seed=2)
    assert len(units) == 4 and units[0] != units[1]
    data = calibration_data(design, units, step_deg=1.0)
    assert data["volts"].shape == (4 * 31 * 31, 2)
    assert list(dict.fromkeys(data["unit"])) == ["1", "2", "3", "4"]
    first, second = data["volts"][:961], data["volts"][961:1922]
    assert np.abs(first - second).mean() > 0.005  # different gains and offsets
    log = voltage_log(design, units, "roll", cycles=1, samples_per_cycle=8)
    assert log["volts"].shape == (8 * 4, 2)
    assert log["angles_deg"].shape == (8, 4, 2)
    assert_allclose(log["angles_deg"][2, :, 1], 15.0)  # the peak of the roll cycle, 60°/4
    assert_allclose(log["angles_deg"][..., 0], 0.0)
