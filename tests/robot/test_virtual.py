"""The virtual device (reflector_opt.robot._virtual): frames of the independent truth at a rate,
on an injected clock, read back through a pseudo-terminal with faults injected."""

import os
import threading
from pathlib import Path

import numpy as np
import pytest

from reflector_opt.calibration import built_units
from reflector_opt.design import load_design
from reflector_opt.model._forward import voltages
from reflector_opt.robot import Protocol, VirtualDevice
from reflector_opt.robot._protocol import open_link
from reflector_opt.robot._virtual import exact_source, pseudo_terminal
from tests.independent.inuse import readings

DESIGN = load_design(Path(__file__).resolve().parents[2] / "examples" / "data" / "design.json")
UNITS = built_units(DESIGN, 3, seed=5)
RATE_HZ = 200.0


def truth(pose, t_s):
    """Each built unit's gain and offset on the independent truth's readings
    (tests/independent/inuse.py: its own circuit, the exact reference's couplings)."""
    gain = np.array([u.gain for u in UNITS])
    offset = np.array([u.offset_v for u in UNITS])
    return gain * readings(DESIGN, pose[:, 0], pose[:, 1]) + offset


def trajectory(t_s):
    """The units bending in pitch, ±12° at 1 Hz, and rolling 3° less each unit along."""
    pitch = 12.0 * np.sin(2 * np.pi * t_s) * np.ones(3)
    return np.column_stack([pitch, [0.0, -3.0, -6.0]])


class FakeClock:
    """Time that moves only when slept, or when a write costs time."""

    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now

    def sleep(self, seconds):
        self.now += seconds


def test_the_frames_are_the_independent_truth_at_the_trajectory_s_poses():
    """Frame k is the truth at t = k / rate, to float32's step (binary volts); the fast model's
    voltages differ from it by far more than that (the source is not the estimator's model)."""
    protocol = Protocol(3, temperature=True)
    clock = FakeClock()
    device = VirtualDevice(protocol, truth, trajectory, RATE_HZ, clock=clock, sleep=clock.sleep)
    chunks = []
    device.run(chunks.append, 20)
    frames = protocol.decoder().feed(b"".join(chunks))
    assert [f.counter for f in frames] == list(range(20))
    for frame in frames:
        pose = trajectory(frame.counter / RATE_HZ)
        np.testing.assert_allclose(frame.readings, truth(pose, 0), rtol=0, atol=3e-7)
        np.testing.assert_allclose(frame.temperature_c, 25.0)
    pose = trajectory(0.1)
    fast = np.array([u.gain for u in UNITS]) * voltages(DESIGN, pose[:, 0], pose[:, 1])
    assert np.abs(fast + [u.offset_v for u in UNITS] - truth(pose, 0)).max() > 1e-5
    assert device.sent == 20 and device.overruns == 0 and device.max_lag_s == 0.0


def test_a_slow_write_is_an_overrun_the_receiver_sees_as_dropped_frames():
    """Frame 5's write takes 3.5 periods: frame 6 is due 2.5 periods before the clock, so slots
    6 and 7 are missed (overruns 2, the largest lag 2.5 periods) and frame 8 is sent, 0.5
    period late; the decoder counts the 2 missing frames as dropped. No real time passes."""
    protocol = Protocol(3)
    clock = FakeClock()
    device = VirtualDevice(protocol, truth, trajectory, RATE_HZ, clock=clock, sleep=clock.sleep)
    decoder = protocol.decoder()
    counters = []

    def write(data):
        counters.extend(f.counter for f in decoder.feed(data))
        if counters[-1] == 5:
            clock.now += 3.5 / RATE_HZ

    device.run(write, 10)
    assert counters == [0, 1, 2, 3, 4, 5, 8, 9, 10, 11]
    assert device.overruns == decoder.faults["dropped"] == 2
    assert device.max_lag_s == pytest.approx(2.5 / RATE_HZ, abs=1e-12)


def test_the_decoder_counts_each_fault_through_a_pseudo_terminal():
    """The device in a thread writes 30 text frames of ADC codes into a pseudo-terminal; frame
    5 is garbled on the way, 12 and 13 lost, a half frame is the last thing written and, once
    the reader has read it (closing the device's end throws away what the port holds unread),
    the device closes its end (unplugged: the port reads EIO). The reader, reading the port as
    a serial port is read, gets the 27 others and counts 1 text fault, 3 dropped, 1 truncated
    and 1 unplugged."""
    protocol = Protocol(3, adc_bits=12, form="text")
    device_fd, port_fd, port = pseudo_terminal()
    chunks = open_link(port)

    def write(data):
        counter = int(data.split(b",")[0])
        if counter == 5:
            data = data.replace(b",", b";", 1)
        if counter not in (12, 13):
            os.write(device_fd, data)

    def run():
        clock = FakeClock()
        VirtualDevice(protocol, truth, trajectory, RATE_HZ, clock=clock, sleep=clock.sleep).run(
            write, 30
        )
        os.write(device_fd, b"30,1,2")
        assert everything_read.wait(timeout=60)
        os.close(port_fd)
        os.close(device_fd)

    def watched(chunks):
        for chunk in chunks:
            yield chunk
            if chunk.endswith(b"30,1,2"):
                everything_read.set()

    everything_read = threading.Event()
    thread = threading.Thread(target=run)
    thread.start()
    decoder = protocol.decoder()
    counters = [f.counter for f in decoder.read(watched(chunks))]
    thread.join()
    assert counters == [c for c in range(30) if c not in (5, 12, 13)]
    faults = {"text": 1, "dropped": 3, "truncated": 1, "unplugged": 1}
    assert decoder.faults == {k: faults.get(k, 0) for k in decoder.faults}


def test_the_exact_source_is_the_reference_path_with_each_unit_s_gain_and_offset():
    """:func:`exact_source` against the independent truth at the calibration state: the same
    couplings through two circuits written apart agree to 0.2 mV (0.10 mV measured), and a
    wrong-signed offset (about 20 mV) leaves that."""
    pose = trajectory(0.2)
    source = exact_source(DESIGN, UNITS)
    assert np.abs(source(pose, 0.0) - truth(pose, 0.0)).max() < 2e-4
    flipped = [type(u)(u.gain, tuple(-np.asarray(u.offset_v))) for u in UNITS]
    assert np.abs(exact_source(DESIGN, flipped)(pose, 0.0) - truth(pose, 0.0)).max() > 2e-4
