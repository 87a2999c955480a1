"""A virtual device: built units of a design sending frames at a rate along a trajectory.

For tests, demos and users without hardware yet. The readings come from any ``source``
callable; :func:`exact_source` gives the package's exact reference path
(:func:`reflector_opt.model._reference.direct_response`: a rotation per pose and the surface
couplings at every pose, no interpolation) with each built unit's gain and offset, not the
estimator's fast model. Time comes from an injectable ``clock`` and ``sleep``, so that lag and
overrun are tested without waiting: frame k is due at t0 + k / rate; a frame sent a whole
period late or more means the slots between were missed (an overrun), and the counter skips
them, as a board's timer would, so a receiver sees them as dropped.
"""

import math
import os
import time
import tty

import numpy as np

from reflector_opt.robot._protocol import Frame


class VirtualDevice:
    """Units sending frames of a :class:`~reflector_opt.robot._protocol.Protocol`.

    Parameters
    ----------
    protocol : reflector_opt.robot._protocol.Protocol
    source : callable
        ``source(pose_deg, t_s)`` → readings, V, shape (n_units, n_sensors), for the units'
        (pitch, roll) ``pose_deg`` of shape (n_units, 2), degrees, at time ``t_s``, s.
    trajectory : callable
        ``trajectory(t_s)`` → the units' (pitch, roll), shape (n_units, 2), degrees.
    rate_hz : float
        Frames per second.
    temperature_c : float or callable
        Each unit's temperature, °C, or ``temperature_c(t_s)`` → shape (n_units,) (sent when
        the protocol has temperatures).
    clock, sleep : callable
        ``clock()`` → s, and ``sleep(s)``: :func:`time.monotonic` and :func:`time.sleep`.

    Attributes
    ----------
    sent : int
        Frames sent.
    overruns : int
        Slots missed by sending late (the counter skipped them).
    max_lag_s : float
        The latest a frame was sent after its slot, s.
    """

    def __init__(
        self,
        protocol,
        source,
        trajectory,
        rate_hz,
        *,
        temperature_c=25.0,
        clock=time.monotonic,
        sleep=time.sleep,
    ):
        self.protocol, self.source, self.trajectory = protocol, source, trajectory
        self.period_s = 1.0 / rate_hz
        self.temperature_c, self.clock, self.sleep = temperature_c, clock, sleep
        self.sent, self.overruns, self.max_lag_s = 0, 0, 0.0

    def frame(self, counter, t_s):
        """The frame of slot ``counter`` at time ``t_s`` (s from the start)."""
        p = self.protocol
        pose = np.asarray(self.trajectory(t_s), dtype=float).reshape(p.n_units, 2)
        readings = np.asarray(self.source(pose, t_s), dtype=float).reshape(p.n_units, -1)
        if p.adc_bits is not None:  # the ADC: code = round(V / LSB), clipped
            lsb = p.adc_reference_v / 2**p.adc_bits
            readings = np.clip(np.rint(readings / lsb), 0, 2**p.adc_bits - 1)
        temps = None
        if p.temperature:
            value = self.temperature_c(t_s) if callable(self.temperature_c) else self.temperature_c
            temps = np.broadcast_to(np.asarray(value, dtype=float), (p.n_units,))
        return Frame(counter, readings, temps)

    def run(self, write, n_frames):
        """Send ``n_frames`` frames at the rate, each as bytes to ``write``.

        Parameters
        ----------
        write : callable
            ``write(bytes)``: ``os.write`` to a pseudo-terminal, a UDP socket's ``sendto``, a
            file's ``write``.
        n_frames : int

        Returns
        -------
        VirtualDevice
            Itself, with ``sent``, ``overruns`` and ``max_lag_s``.
        """
        start, slot = self.clock(), 0
        for _ in range(n_frames):
            due = start + slot * self.period_s
            now = self.clock()
            if now < due:
                self.sleep(due - now)
                now = max(self.clock(), due)
            self.max_lag_s = max(self.max_lag_s, now - due)
            missed = math.floor((now - due) / self.period_s)
            self.overruns += missed
            slot += missed
            write(self.protocol.encode(self.frame(slot, slot * self.period_s)))
            self.sent += 1
            slot += 1
        return self


def exact_source(design, units):
    """Readings of built units by the exact reference path, for :class:`VirtualDevice`.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    units : list of reflector_opt.model._noise.Mismatch
        Each unit's per-sensor gain and offset (:func:`~reflector_opt.calibration.built_units`).

    Returns
    -------
    callable
        ``source(pose_deg, t_s)`` → V, shape (n_units, n_sensors): ``gain ·
        direct_response(design, pitch, roll) + offset`` per unit.
    """
    from reflector_opt.model._reference import direct_response

    gain = np.array([u.gain for u in units])
    offset = np.array([u.offset_v for u in units])
    return lambda pose, t_s: gain * direct_response(design, pose[:, 0], pose[:, 1])[2] + offset


def pseudo_terminal():
    """A pseudo-terminal in raw mode, as a serial port stands in for a device.

    Returns
    -------
    (int, int, str)
        The device side's file descriptor (write frames to it), the port side's descriptor
        and the port's path (read it as a serial port or a file:
        :func:`~reflector_opt.robot._protocol.open_link`). Closing the device's end unplugs
        the port (its reader's next read fails with EIO) and throws away what the port holds
        unread: close it once the reader has read what it needs.
    """
    device, port = os.openpty()
    tty.setraw(port)  # bytes as they are: no echo, no line editing, no newline translation
    return device, port, os.ttyname(port)
