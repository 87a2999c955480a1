"""A reference sensor on a cap of its own, centred on the joint's rotation centre, judged in use.

benchmarks/third_sensor.py judges the layouts; this module holds its key comparison in
examples/conditions.toml: the pair's drops ratioed by the reference's (the budget's fitted
common gain, ``error_budget(nuisance=…)``) against the independent truth's exact ratio
(tests/independent/inuse.py: its own circuit and inversion) pose by pose within 25 %, the
temperature drift it cancels below 1 % of the pair's, and the same comparison failing when
the pair's correction has the wrong sign.
"""

import importlib.util
import logging
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from reflector_opt.design import load_design
from reflector_opt.design._conditions import load_conditions
from tests.independent.inuse import in_use_error_deg

ROOT = Path(__file__).resolve().parents[2]
TOLERANCE = 0.25
STEP_DEG = 5.0


@cache
def _bench():
    spec = importlib.util.spec_from_file_location(
        "third_sensor", ROOT / "benchmarks" / "third_sensor.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@cache
def _case(gap="peak"):
    logging.disable(logging.WARNING)  # the bearing's rated tilt
    bench = _bench()
    design = load_design(ROOT / "examples" / "data" / "design.json")
    layout = bench.with_sensor(design, 180.0, "R")
    gap_mm = bench.peak_gap_mm(layout) if gap == "peak" else design.models[0].range_mm[0]
    return bench, design, layout, gap_mm, load_conditions(ROOT / "examples" / "conditions.toml")


def _budget(nuisance, gap="peak"):
    bench, _, layout, gap_mm, conditions = _case(gap)
    return bench.budget_of(layout, [gap_mm], nuisance, conditions, step_deg=STEP_DEG)


def _truth(budget, term, gap="peak"):
    bench, _, layout, gap_mm, _ = _case(gap)
    states = bench.truth_states(budget)[term]
    return bench.ratio_truth(
        layout, gap_mm, states, budget.pitch_deg.ravel(), budget.roll_deg.ravel()
    )


def _wrong_sign(grid):
    """The pair's correction reversed: its drops multiplied by the reference's ratio."""
    column = _bench().gain(grid)
    column[..., :-1, :] *= -1.0
    return column


def test_the_reference_sits_at_its_response_peak_and_its_reading_does_not_turn_with_the_joint():
    bench, _, layout, gap_mm, _ = _case()
    (radius,) = bench.cap_radii_mm(layout, [gap_mm])
    reading = lambda d, p=0.0, r=0.0: bench.cap_outputs(  # noqa: E731
        layout, bench.cap_radii_mm(layout, [d])[0], p, r
    )[-1]
    assert 0.1 < gap_mm < 0.5  # below the NJL5901R-2's usable range, 0.5–3 mm
    assert reading(gap_mm) < min(reading(gap_mm - 0.02), reading(gap_mm + 0.02))
    turned = bench.cap_outputs(layout, radius, np.array([15.0, -15.0]), np.array([-15.0, 15.0]))
    np.testing.assert_allclose(turned[:, -1], reading(gap_mm), rtol=1e-9)


@pytest.mark.parametrize("term", ["temperature", "supply"])
def test_the_ratio_to_the_reference_matches_the_truth_and_fails_with_the_wrong_sign(term):
    """What the ratio changes of the pair's error (its correction), by the budget and by the
    truth, pose by pose; the temperature drift it cancels below 1 % of the pair's."""
    bench, design, _, _, conditions = _case()
    pair = bench.budget_of(design, [], None, conditions, step_deg=STEP_DEG)
    right, wrong = _budget(bench.gain), _budget(_wrong_sign)
    pitch, roll = pair.pitch_deg.ravel(), pair.roll_deg.ravel()
    states = bench.truth_states(pair)[term]
    alone = np.stack([in_use_error_deg(design, pitch, roll, s) for s in states])
    truth = _truth(right, term) - alone
    assert bench.gap(right.scenarios[term] - pair.scenarios[term], truth) < TOLERANCE
    assert bench.gap(wrong.scenarios[term] - pair.scenarios[term], truth) > TOLERANCE
    if term == "temperature":
        scale = np.abs(alone).max()
        assert np.abs(truth + alone).max() < 0.01 * scale
        assert np.abs(right.scenarios[term]).max() < 0.01 * scale


@pytest.mark.slow
def test_a_reference_in_the_usable_range_reads_the_joints_shift_as_the_truth_does():
    """At 0.5 mm the reference reads the joint's shift along its line of sight as a gain
    change: the play term grows from the pair's, and the truth agrees pose by pose."""
    pair = _case()[0].budget_of(_case()[1], [], None, _case()[4], step_deg=STEP_DEG)
    right, wrong = _budget(_bench().gain, "near"), _budget(_wrong_sign, "near")
    truth = _truth(right, "play", "near")
    gap = _bench().gap
    assert np.abs(right.scenarios["play"]).max() > 1.3 * np.abs(pair.scenarios["play"]).max()
    assert gap(right.scenarios["play"], truth) < TOLERANCE
    assert gap(wrong.scenarios["play"], truth) > TOLERANCE


def test_the_reference_at_its_peak_buys_what_a_thermometer_does_in_the_conditions_file():
    """The benchmark's verdict on its 1° grid, held here on the 5° grid: R at its peak is at
    least 1.5× better than the pair read straight in examples/conditions.toml, and within 10 %
    of the pair with a thermometer (no extra sensor)."""
    bench, design, _, _, conditions = _case()
    pair = bench.budget_of(design, [], None, conditions, step_deg=STEP_DEG).worst_case_deg
    thermometer = bench.budget_of(
        design, [], None, conditions.replace(temperature_compensated=True), step_deg=STEP_DEG
    ).worst_case_deg
    ratio = _budget(bench.gain).worst_case_deg
    assert pair / ratio > 1.5
    assert abs(ratio / thermometer - 1.0) < 0.10
    assert pair / _budget(_wrong_sign).worst_case_deg < 1.0
