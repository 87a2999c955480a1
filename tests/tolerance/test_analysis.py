"""One unit's analysis: the read-out by hand, the nominal design, calibration, collisions."""

import math

import numpy as np
from numpy.testing import assert_allclose

from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.calibration._models import make_model
from reflector_opt.calibration._simulation import assess, run_protocol
from reflector_opt.model._noise import Mismatch
from reflector_opt.tolerance import (
    Job,
    Spread,
    Tolerances,
    as_built,
    draw_sample,
    evaluate_draw,
)
from reflector_opt.tolerance._analysis import passes, read_out
from reflector_opt.tolerance._config import parse_tolerance_config
from reflector_opt.tolerance._tolerances import Electrical
from tests.tolerance.fast import FAST


def test_read_out_hand_values(design):
    volts = np.array([[1.0, 2.0], [3.0, 0.5]])
    electrical = Electrical(Mismatch(), np.array([0.1, 0.2]), np.array([10.0, 0.0]))
    # NJL5901R-2: Vcc 3.3 V, R2 10 kΩ, no dark current, V_CE(sat) from the preset
    vsat = design.models[0].saturation_v
    calibration = read_out(design, electrical, volts, in_use=False)
    assert_allclose(
        calibration,
        [[1.0 - 0.1 * 1.3, 2.0 - 0.2 * 2.3], [3.0 - 0.1 * 2.8, max(0.5 - 0.2 * 0.3, vsat)]],
    )
    in_use = read_out(design, electrical, volts, in_use=True)
    assert_allclose(in_use[:, 0], calibration[:, 0] - 10e-6 * 1e4)  # 10 µA · 10 kΩ = 0.1 V
    assert_allclose(in_use[:, 1], calibration[:, 1])
    none = Electrical(Mismatch(), np.zeros(2), np.zeros(2))
    assert np.array_equal(read_out(design, none, volts, in_use=True), volts)


def test_zero_tolerances_give_the_nominal_design_exactly(design):
    """Independent path: the simulation module's own protocol and the metrics of the design."""
    job = Job(design, Tolerances.zero(), FAST)
    template = make_model("eq6")
    for index in range(3):
        draw = draw_sample(Tolerances(), 2, seed=11, index=index)
        built, _ = as_built(design, Tolerances.zero(), draw)
        assert built == design
        record = evaluate_draw(job, draw)
        protocol = run_protocol(design, step_deg=2.0, n_validation=300, seed=draw.noise_seed)
        reference = assess(template, protocol)
        metrics = evaluate_metrics(design, 2.0)
        assert record["status"] == "ok"
        assert record["rms_pitch_deg"] == reference.total.rms_deg[0]
        assert record["rms_roll_deg"] == reference.total.rms_deg[1]
        assert record["max_pitch_deg"] == reference.total.max_deg[0]
        assert record["max_roll_deg"] == reference.total.max_deg[1]
        assert record["distance_margin_mm"] == metrics.distance_margin_mm.min()
        assert record["resolution_pitch_deg"] == metrics.worst_pitch_deg
        assert record["window_kept"] is True


def test_calibration_absorbs_gain_and_offset_but_not_ambient_light(design):
    """Gain and offset are present in calibration and use: Eq 6 (with a constant term) fitted
    on the unit absorbs most of them. Ambient light in use only is not absorbed."""
    draw = draw_sample(Tolerances(), 2, seed=3, index=0)
    base = evaluate_draw(Job(design, Tolerances.zero(), FAST), draw)
    gain = Tolerances(**_only(gain=Spread(0.05)))
    ambient = Tolerances(**_only(ambient_current_ua=Spread(20.0, "uniform")))
    with_gain = evaluate_draw(Job(design, gain, FAST), draw)
    with_ambient = evaluate_draw(Job(design, ambient, FAST), draw)
    assert with_gain["rms_pitch_deg"] < base["rms_pitch_deg"] + 0.05
    assert with_ambient["rms_pitch_deg"] > base["rms_pitch_deg"] + 0.1


def _only(**spreads):
    return {name: Spread(0.0) for name in Tolerances.names()} | spreads


def test_a_unit_built_into_a_collision_is_reported_not_raised(design):
    tol = Tolerances(**_only(sensor_position_mm=Spread(5.0)))
    records = [evaluate_draw(Job(design, tol, FAST), draw_sample(tol, 2, 0, i)) for i in range(8)]
    invalid = [r for r in records if r["status"] == "invalid"]
    unfit = [r for r in records if r["status"] == "unfit"]
    assert invalid, "5 mm placement errors push some sensor into the sphere"
    assert all(not r["window_kept"] and math.isnan(r["rms_pitch_deg"]) for r in invalid)
    assert all(math.isnan(r["rms_pitch_deg"]) for r in unfit)
    assert not any(passes(r, parse_tolerance_config({}).targets) for r in invalid + unfit)
