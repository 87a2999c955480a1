"""The calibration figures: error maps, angle traces, a segment's motion and its tip path."""

import numpy as np
import pytest

from reflector_opt.calibration._segment import simulate_segment
from reflector_opt.calibration._simulation import simulate_calibration
from reflector_opt.report.figures._calibration import (
    angle_traces_figure,
    calibration_error_figure,
    segment_figure,
    tip_path_figure,
)
from tests.report.figures.drawing import PITCH, ROLL, axis_labels, render


@pytest.fixture(scope="module")
def calibration(design):
    return simulate_calibration(design, "eq6", step_deg=1.0, n_validation=500)


def test_calibration_error_maps(calibration):
    fig = render(lambda: calibration_error_figure(calibration))
    main, bars = axis_labels(fig)
    assert main == [(PITCH, ROLL)] * 2
    assert bars == ["pitch error (°)", "roll error (°)"]


def test_angle_traces_report_the_rms_error():
    true = np.zeros((50, 2))
    estimate = np.column_stack([np.full(50, 0.5), np.full(50, -2.0)])
    fig = render(lambda: angle_traces_figure(true, estimate, "Fig. 5"))
    assert [ax.get_ylabel() for ax in fig.axes] == ["pitch (°)", "roll (°)"]
    assert fig.axes[-1].get_xlabel() == "sample (–)"
    assert "0.500°" in fig.axes[0].get_title() and "2.000°" in fig.axes[1].get_title()


def test_segment_estimate_against_truth(design, calibration):
    errors = simulate_segment(design, calibration.model, "roll", cycles=1, samples_per_cycle=50)
    fig = render(lambda: segment_figure(errors))
    assert [ax.get_ylabel() for ax in fig.axes] == ["tip roll (°)", "roll error (°)"]
    assert fig.axes[1].get_xlabel() == "sample (–)"


def test_tip_paths_reach_the_chain_length_when_straight(design):
    fig = render(lambda: tip_path_figure(design))
    main, _ = axis_labels(fig)
    assert main == [("x (mm)", "z (mm)"), ("y (mm)", "z (mm)")]
    mech = design.mechanics
    # the straight pose's chain ends at n_units × link length on the z axis
    straight = fig.axes[0].lines[-2]  # drawn last before the legend handle
    assert straight.get_ydata()[-1] == pytest.approx(mech.n_units * mech.link_length_mm)
    assert straight.get_xdata()[-1] == pytest.approx(0.0)
