"""Live angles (reflector_opt.robot._stream): the virtual device's frames, fed the independent
truth, to each unit's pitch and roll and their 1σ."""

import numpy as np
import pytest

from reflector_opt.calibration import Eq5, Eq6
from reflector_opt.calibration._unit_calibration import UnitCalibration
from reflector_opt.robot import Protocol, VirtualDevice, _stream
from reflector_opt.robot._stream import stream
from reflector_opt.util._errors import InputError
from tests.robot.test_virtual import RATE_HZ, FakeClock, trajectory, truth

GRID = np.array([(p, r) for p in np.linspace(-15, 15, 13) for r in np.linspace(-15, 15, 13)])


def _calibrations(form):
    """Each of the three built units calibrated on the truth over a 2.5° grid, ±15°."""
    volts = np.stack([truth(np.repeat([pose], 3, axis=0), 0) for pose in GRID], axis=1)
    return [UnitCalibration(str(j + 1), form().fit(volts[j], GRID)) for j in range(3)]


def _frames(protocol, n=25):
    clock = FakeClock()
    device = VirtualDevice(protocol, truth, trajectory, RATE_HZ, clock=clock, sleep=clock.sleep)
    chunks = []
    device.run(chunks.append, n)
    return protocol.decoder().feed(b"".join(chunks))


def test_the_angles_are_predict_s_on_the_frames_and_near_the_truth():
    """Each unit's angles equal its calibration's ``predict`` of the frame's volts (1e-9°), and
    lie within 4 σ of the trajectory's truth (σ: the training RMS and 0.5 mV of noise)."""
    protocol = Protocol(3)
    calibrations = _calibrations(Eq6)
    frames = _frames(protocol)
    out = list(stream(frames, protocol, calibrations, noise_v=5e-4))
    assert [a.counter for a in out] == list(range(25))
    for frame, estimate in zip(frames, out, strict=True):
        expected = [c.model.predict(v) for c, v in zip(calibrations, frame.readings, strict=True)]
        np.testing.assert_allclose(estimate.angles_deg, expected, rtol=0, atol=1e-9)
        error = estimate.angles_deg - trajectory(frame.counter / RATE_HZ)
        assert (np.abs(error) < 4 * estimate.sigma_deg).all()


def test_sigma_is_the_calibration_error_and_the_noise_through_the_linear_map():
    """Eq 5 is linear, v ↦ K v: J = K exactly, so σ_k² = e_k² + σ_V²(K_k1² + K_k2²) by hand,
    with e the training RMS; a doubled Jacobian (the guard) fails the comparison."""
    protocol = Protocol(3)
    calibrations = _calibrations(Eq5)
    frames = _frames(protocol, 3)
    noise = 2e-3
    expected = np.array(
        [
            np.sqrt(c.model.training_rms_deg_**2 + noise**2 * (c.model.coef_**2).sum(axis=1))
            for c in calibrations
        ]
    )
    for estimate in stream(frames, protocol, calibrations, noise_v=noise):
        np.testing.assert_allclose(estimate.sigma_deg, expected, rtol=1e-6)
    estimate = _stream.PreparedUnits.estimate  # the units' Jacobians, evaluated together

    def doubled(*args, **kwargs):
        angles, jacobians = estimate(*args, **kwargs)
        return angles, 2 * jacobians

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(_stream.PreparedUnits, "estimate", doubled)
        wrong = next(stream(frames, protocol, calibrations, noise_v=noise)).sigma_deg
    assert not np.allclose(wrong, expected, rtol=1e-6)


def test_frames_with_a_unit_the_calibration_lacks_are_refused_in_one_line():
    with pytest.raises(
        InputError, match=r"^frames: 4 units, but the calibration has 3 \(1, 2, 3\)$"
    ):
        next(stream([], Protocol(4), _calibrations(Eq5)))


def test_a_compensated_calibration_reads_each_frame_s_temperature():
    """Unit 1 calibrated compensated (Eq 6) on the independent truth at 20, 25 and 30 °C (its
    own temperature physics: LED forward voltage and dark current, and an assumed −0.5 %/K
    output, the part publishing no curve), then streamed from
    a device at 28 °C: the angles equal ``predict`` at the frame's temperature (1e-9°) and
    follow the truth within 0.3°, where the same frames read as at 25 °C (uncompensated) drift
    further."""
    from reflector_opt.calibration import TemperatureCompensated
    from tests.independent.inuse import InUse, readings
    from tests.robot.test_virtual import DESIGN

    def at(delta_k):  # the part has no published output curve: −0.5 %/K assumed
        state = InUse(delta_k, linear_output_per_k=-0.005)
        return lambda pose, t_s: readings(DESIGN, pose[:, 0], pose[:, 1], state)

    volts = np.concatenate([at(dt)(GRID, 0) for dt in (-5.0, 0.0, 5.0)])
    temps = np.repeat([20.0, 25.0, 30.0], len(GRID))
    model = TemperatureCompensated("eq6").fit(volts, np.tile(GRID, (3, 1)), temps)
    calibrations = [UnitCalibration("1", model)]
    plain = Eq6().fit(at(0.0)(GRID, 0), GRID)
    protocol = Protocol(1, temperature=True)
    clock = FakeClock()
    device = VirtualDevice(
        protocol,
        at(3.0),
        lambda t: trajectory(t)[:1],
        RATE_HZ,
        temperature_c=28.0,
        clock=clock,
        sleep=clock.sleep,
    )
    chunks = []
    device.run(chunks.append, 20)
    frames = protocol.decoder().feed(b"".join(chunks))
    for frame, estimate in zip(frames, stream(frames, protocol, calibrations), strict=True):
        np.testing.assert_allclose(
            estimate.angles_deg[0], model.predict(frame.readings[0], 28.0), rtol=0, atol=1e-9
        )
        true = trajectory(frame.counter / RATE_HZ)[0]
        assert np.abs(estimate.angles_deg[0] - true).max() < 0.1
    drift = max(
        np.abs(plain.predict(f.readings[0]) - trajectory(f.counter / RATE_HZ)[0]).max()
        for f in frames
    )
    assert drift > 0.3


def test_prepared_units_evaluate_each_unit_s_predict_and_jacobian_together():
    """Four units of four forms (Eq 5, Eq 6, poly3, and Eq 6 compensated), evaluated at once:
    each unit's angles equal its ``unit_angles`` (1e-9°) and its Jacobian the central
    differences ``angle_sigma`` takes (1e-6 relative); two units' coefficients swapped (the
    guard) fail the comparison. A temperature the compensation cannot take is refused as
    ``estimate`` refuses it, naming the unit."""
    from reflector_opt.calibration import Polynomial, TemperatureCompensated
    from reflector_opt.calibration._unit_calibration import unit_angles, unit_jacobian
    from reflector_opt.robot._stream import PreparedUnits

    volts = np.stack([truth(np.repeat([pose], 3, axis=0), 0) for pose in GRID], axis=1)
    warm = 3.3 - (3.3 - volts[0]) * 0.97 - 5e-4  # Eq (1) at +6 K: c = -0.5 %/K, d = 83 µV/K
    compensated = TemperatureCompensated("eq6").fit(
        np.concatenate([volts[0], warm]), np.tile(GRID, (2, 1)), np.repeat([22.0, 28.0], len(GRID))
    )
    forms = [Eq5().fit(volts[0], GRID), Eq6().fit(volts[1], GRID)]
    forms += [Polynomial(3).fit(volts[2], GRID), compensated]
    units = [UnitCalibration(str(j + 1), m) for j, m in enumerate(forms)]
    readings = np.stack([volts[0][:7], volts[1][:7], volts[2][:7], warm[:7]], axis=1)
    temps = np.tile([25.0, 25.0, 25.0, 27.0], (7, 1))
    prepared = PreparedUnits(units)
    angles, jacobians = prepared.estimate(readings, temps)
    for j, c in enumerate(units):
        t = temps[:, j]
        np.testing.assert_allclose(angles[:, j], unit_angles(c, readings[:, j], t), atol=1e-9)
        np.testing.assert_allclose(jacobians[:, j], unit_jacobian(c, readings[:, j], t), rtol=1e-6)
    prepared.coef[[0, 1]] = prepared.coef[[1, 0]]
    swapped, _ = prepared.estimate(readings, temps)
    assert np.abs(swapped - angles).max() > 1.0
    with pytest.raises(InputError, match=r"^unit 4: temperature_c: .*looks like kelvin"):
        PreparedUnits(units).estimate(readings, np.full((7, 4), 300.0))


def test_a_block_s_csv_rows_read_back_as_estimate_s_writer_s_exactly():
    """``csv_rows`` (one format string a line) and ``EstimatedShape.append_to`` (pyarrow's CSV
    writer) give the same header and, read back, the same floats bit for bit (a zero, a
    negative zero and a σ's NaN too); only the numbers' text form may differ."""
    import csv
    import io

    from reflector_opt.robot._stream import csv_rows, estimate_block

    protocol = Protocol(3)
    frames = _frames(protocol, 4)
    shape = estimate_block(frames, protocol, _calibrations(Eq6), noise_v=1e-3, link_length_mm=18)
    shape.sigma_deg[0, 0] = np.nan
    shape.tip_angles_deg[1] = [0.0, -0.0, 1e-5]
    written = io.BytesIO()
    shape.append_to(written, header=True)

    def rows(data):
        header, *lines = csv.reader(io.StringIO(data.decode()))
        return header, [line[0] for line in lines], np.array(lines)[:, 1:].astype(float)

    ours, theirs = rows(csv_rows(shape, header=True)), rows(written.getvalue())
    assert ours[:2] == theirs[:2] and ours[2].shape == (4, 2 * 3 + 6 + 2 * 3)
    np.testing.assert_array_equal(ours[2].view(np.int64), theirs[2].view(np.int64))
