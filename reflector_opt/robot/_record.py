"""A calibration run live: the device's frames and an angle reference, pose by pose of a plan.

The **reference** (an IMU, or the robot's encoders turned into each unit's angles) sends text
lines ``time_s,unit,pitch_deg,roll_deg`` (that header optional), one per sample and unit, on
its own clock, over any link :func:`~reflector_opt.robot._protocol.open_link` opens. Device
unit j (base first) is labelled ``j + 1``. Every pose of the plan is commanded to every unit.

The two clocks are aligned from the samples' times: a sample stamped s that arrives at t (the
run's clock) was taken at s + θ, θ = min(t − s) over the samples so far, the least delayed
sample's (the clocks' offset plus the link's shortest delay; a clock that drifts by r moves
this by r per second, 1 ms over 100 s at 10 ppm). A sample arriving more than ``late_s`` after
s + θ is counted ``late``; no sample for ``stop_s`` is a stop (``stopped``, once per silence),
during which no pose is taken.

Pose i is taken at the run's time t when, over the window (t − ``window_s``, t], all of it
after the pose became the next one: every reading's standard deviation is at most
``spread_v``, every unit's reference samples lie within ``tolerance_deg`` of the pose (in
pitch and in roll) and the latest is current (within ``late_s`` of t). The sample kept per
unit is the window's mean voltages, median reference angles (the calibration's truth, not the
plan's nominal pose; the median, because θ holds the link's shortest delay, so the window's
first reference sample may be the end of the move) and mean temperature. A pose the
reference reached and then left before a window settled is dropped as ``moved``; one not
taken within ``timeout_s`` as ``missed``.
"""

import queue
import threading
import time
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from reflector_opt.util._errors import InputError

#: The faults a recording counts beside its decoder's: a reference line that is not a sample
#: of a device unit; a reference sample late; a reference that stopped; poses dropped.
FAULTS = ("reference_text", "late", "stopped", "moved", "missed")


@dataclass
class Recorder:
    """The state of a calibration run, fed the device's and the reference's bytes in time order.

    Parameters
    ----------
    protocol : reflector_opt.robot._protocol.Protocol
        The device's frames (two sensors per unit, as ``calibrate`` reads them).
    poses_deg : numpy.ndarray
        Shape (n, 2): the plan's pitch and roll in visiting order, degrees.
    window_s, spread_v, tolerance_deg, timeout_s, stop_s, late_s : float
        The settling window, s; the largest standard deviation of a reading in it, V; the
        reference's tolerance, degrees; the wait for a pose, s; the silence of a stopped
        reference, s; the delay of a late sample, s (module notes).
    progress : callable or None
        ``progress(fraction, message)``: which pose is next, each pose's outcome.

    Attributes
    ----------
    rows : list of tuple
        Per kept pose and unit: (unit, v1, v2, pitch_deg, roll_deg, temperature_c or None).
    kept : list of tuple
        Per kept pose: (pose index, largest reading std in V, largest reference deviation
        from the pose in degrees).
    offset_s, max_lag_s : float or None
        θ, and the largest delay of a reference sample beyond it, s.
    """

    protocol: object
    poses_deg: np.ndarray
    window_s: float = 0.5
    spread_v: float = 1e-3
    tolerance_deg: float = 0.5
    timeout_s: float = 30.0
    stop_s: float = 1.0
    late_s: float = 0.2
    progress: object = None
    rows: list = field(default_factory=list)
    kept: list = field(default_factory=list)
    offset_s: float | None = None
    max_lag_s: float = 0.0

    def __post_init__(self):
        if self.protocol.n_sensors != 2:
            raise InputError(f"n_sensors: calibrate reads v1 and v2, got {self.protocol.n_sensors}")
        self.decoder = self.protocol.decoder()
        self._faults = dict.fromkeys(FAULTS, 0)
        self.labels = [str(j + 1) for j in range(self.protocol.n_units)]
        self._frames, self._reference, self._text, self._latest = deque(), deque(), bytearray(), {}
        self._last_reference, self._stopped = None, False
        self._start(0, None)

    @property
    def faults(self):
        """The decoder's faults and :data:`FAULTS`, counted."""
        return self.decoder.faults | self._faults

    @property
    def done(self):
        """Every pose taken or dropped."""
        return self._pose >= len(self.poses_deg)

    def feed(self, t_s, source, data):
        """Take ``data`` (bytes) that arrived at ``t_s`` (s, the run's clock) from ``source``,
        ``"device"`` or ``"reference"``."""
        if source == "reference":
            self._samples(t_s, data)
            return
        for frame in self.decoder.feed(data):
            temps = frame.temperature_c if self.protocol.temperature else None
            self._frames.append((t_s, self.protocol.volts(frame), temps))
        if self._last_reference is not None and t_s - self._last_reference > self.stop_s:
            self._faults["stopped"] += not self._stopped
            self._stopped = True
        if not self.done:
            self._judge(t_s)

    def _samples(self, t_s, data):
        """Reference lines: the clocks' offset, the late ones, the samples kept aligned."""
        self._text += data
        *lines, rest = self._text.split(b"\n")
        self._text = bytearray(rest)
        for line in filter(None, (raw.strip() for raw in lines)):
            if line.startswith(b"time_s,"):  # a header
                continue
            try:
                stamp, unit, pitch, roll = line.decode("ascii").split(",")
                stamp, j = float(stamp), self.labels.index(unit.strip())
                angles = np.array([pitch, roll], dtype=float)
                if not np.isfinite([stamp, *angles]).all():
                    raise ValueError(line)
            except ValueError:
                self._faults["reference_text"] += 1
                continue
            self.offset_s = min(t_s - stamp, self.offset_s if self.offset_s is not None else np.inf)
            lag = float(t_s - stamp - self.offset_s)
            self._faults["late"] += lag > self.late_s
            self.max_lag_s = max(self.max_lag_s, lag)
            self._reference.append((stamp, j, angles))
            self._latest[j] = angles
            self._last_reference, self._stopped = t_s, False

    def _start(self, pose, outcome):
        """Make ``pose`` the next one, saying how the last ended."""
        self._pose, self._since, self._reached = pose, None, False
        self._frames.clear()
        if self.progress is None:
            return
        n = len(self.poses_deg)
        said = [outcome] if outcome else []
        if not self.done:
            said.append(
                f"next: pose {pose + 1}/{n} ({self.poses_deg[pose][0]:g}°, "
                f"{self.poses_deg[pose][1]:g}°)"
            )
        self.progress(pose / n, "; ".join([*said, coverage_line(self)]))

    def _judge(self, t_s):
        """Take, drop or wait for the next pose at ``t_s``."""
        self._since = t_s if self._since is None else self._since
        i = self._pose
        while self._frames and self._frames[0][0] <= t_s - self.window_s:
            self._frames.popleft()
        start = t_s - self.window_s - (self.offset_s or 0.0)
        while self._reference and self._reference[0][0] <= start:
            self._reference.popleft()
        at = None  # the first pose from the next on where every unit's reference is
        if not self._stopped and len(self._latest) == len(self.labels):
            latest = np.array([self._latest[k] for k in range(len(self.labels))])
            near = np.abs(latest - self.poses_deg[i:, None]).max(axis=(1, 2)) <= self.tolerance_deg
            at = i + int(np.argmax(near)) if near.any() else None
        if self._reached and at != i and not self._stopped:
            self._faults["moved"] += 1
            self._start(i + 1, f"pose {i + 1} dropped: moved during the window")
        elif at is not None and at > i:
            self._faults["missed"] += at - i
            self._start(at, f"pose(s) {i + 1}–{at} dropped: the robot is at pose {at + 1}")
        elif t_s - self._since > self.timeout_s:
            self._faults["missed"] += 1
            self._start(i + 1, f"pose {i + 1} dropped: not settled in {self.timeout_s:g} s")
        elif at == i:
            self._reached = True
            if t_s - self._since >= self.window_s and len(self._frames) >= 2:
                self._take(t_s, self.poses_deg[i], f"pose {i + 1}")

    def _take(self, t_s, pose, label):
        """Keep the window's means, if it is settled and the reference current to ``t_s``."""
        volts = np.array([v for _, v, _ in self._frames])  # (n_frames, n_units, 2)
        spread = volts.std(axis=0).max()
        angles = [
            np.array([a for _, j, a in self._reference if j == k]) for k in range(len(self.labels))
        ]
        current = self._reference and self._reference[-1][0] + self.offset_s >= t_s - self.late_s
        if not (current and all(len(a) for a in angles)):
            return
        deviation = max(np.abs(a - pose).max() for a in angles)
        if spread > self.spread_v or deviation > self.tolerance_deg:
            return
        temps = None
        if self.protocol.temperature:
            temps = np.mean([t for _, _, t in self._frames], axis=0)
        for k, label_k in enumerate(self.labels):
            mean = np.median(angles[k], axis=0)
            t_c = None if temps is None else float(temps[k])
            self.rows.append((label_k, *volts[:, k].mean(axis=0), *mean, t_c))
        self.kept.append((self._pose, float(spread), float(deviation)))
        self._start(
            self._pose + 1,
            f"{label} kept: std ≤ {spread * 1e3:.2f} mV, reference within {deviation:.2f}°",
        )


def coverage_line(recorder):
    """The coverage and quality so far: poses kept of the plan's, the pitch and roll range they
    span of the plan's, the largest reading std and reference deviation of a kept pose."""
    poses = recorder.poses_deg
    if not recorder.kept:
        return f"kept 0/{len(poses)}"
    index, spread, deviation = zip(*recorder.kept, strict=True)
    spans = [
        f"{name} {poses[list(index), k].min():g}…{poses[list(index), k].max():g}° of "
        f"{poses[:, k].min():g}…{poses[:, k].max():g}°"
        for k, name in enumerate(("pitch", "roll"))
    ]
    return (
        f"kept {len(index)}/{len(poses)}, {', '.join(spans)}; std ≤ {max(spread) * 1e3:.2f} mV, "
        f"reference within {max(deviation):.2f}°"
    )


def record(events, recorder):
    """Feed ``events`` to ``recorder`` until the plan is done or the device's link ends.

    Parameters
    ----------
    events : iterable of (float, str, bytes or None)
        ``(t_s, source, data)`` in arrival order (:func:`merged`); ``data`` None is the
        source's link ended (EOF), an ``OSError`` its link lost (the device's: ``unplugged``).
    recorder : Recorder

    Returns
    -------
    Recorder
        The same, fed; the poses left when the device ended are counted ``missed``.
    """
    for t_s, source, data in events:
        if isinstance(data, OSError | None) and source == "device":
            recorder.decoder.faults["unplugged"] += isinstance(data, OSError)
            break
        if data is not None and not isinstance(data, OSError):
            recorder.feed(t_s, source, data)
        if recorder.done:
            break
    recorder.decoder.close()
    recorder._faults["missed"] += len(recorder.poses_deg) - recorder._pose
    return recorder


def merged(links, clock=time.monotonic):
    """The chunks of several links as they arrive, each stamped by ``clock``.

    Parameters
    ----------
    links : dict
        Source name → iterator of bytes (:func:`~reflector_opt.robot._protocol.open_link`),
        each read in a thread of its own.
    clock : callable
        ``clock()`` → s.

    Yields
    ------
    (float, str, bytes or None or OSError)
        As :func:`record` takes them.
    """
    arrived = queue.Queue()

    def pump(name, link):
        try:
            for chunk in link:
                arrived.put((name, chunk))
            arrived.put((name, None))
        except OSError as exc:
            arrived.put((name, exc))

    for name, link in links.items():
        threading.Thread(target=pump, args=(name, link), daemon=True).start()
    while True:
        name, data = arrived.get()
        yield clock(), name, data
