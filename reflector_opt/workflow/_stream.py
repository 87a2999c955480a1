"""Live angles from a device's link, as ``reflector-opt stream`` writes them
(:mod:`reflector_opt.robot._stream`).

The frames that arrive together (one read of the link) are estimated as one block, written to
the CSV as whole lines in one write, unbuffered, so that an interruption or a kill leaves every
complete frame readable and no torn last line; with an MCAP log, the same block goes to it as a
chunk of its own, flushed (:mod:`reflector_opt.robot._mcap`).
Ctrl-C, the link's end and a lost link close both files whole. A stream faster than the
estimator shows as frames waiting: the most that arrived at once is reported, and with
``keep_up`` only the newest of them are estimated, the others counted ``skipped`` (the queue
is the link's own buffer, never one of this run's). With ``view``, each block's newest shape is
also shown live in a browser (:mod:`reflector_opt.robot._live`: shapes dropped to keep up, the
stream never waits for it), until the stream ends, however it ends.
"""

import importlib.util
import time
from contextlib import ExitStack
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal

from reflector_opt.util._declared import Options, option, takes
from reflector_opt.util._display import Printed
from reflector_opt.util._errors import InputError
from reflector_opt.workflow._estimate import (
    InUseConditions,
    InUseDesign,
    LinkLength,
    NoiseV,
    in_use_of,
)


@dataclass(frozen=True, repr=False)
class StreamRun(Printed):
    """A link's frames to angles (:func:`stream`); :meth:`write` runs it.

    Attributes
    ----------
    link : iterator of bytes
        The open link (:func:`~reflector_opt.robot._protocol.open_link`).
    protocol : reflector_opt.robot._protocol.Protocol
    units : list of UnitCalibration
        The frames' units' calibrations, base first.
    options : StreamOptions
    link_length_mm : float
    clock : callable
        ``clock()`` → s since the epoch: the messages' stamps, the lag and ``duration``.
    in_use : list or None
        Each unit's in-use terms for ``--conditions``, in each angle's 1σ.
    counts : dict
        Once written: ``frames`` written, ``skipped``, ``max_backlog`` (frames that arrived
        at once), ``max_lag_ms`` (a block received → written), ``faults`` (the decoder's),
        ``stopped`` (``end``, ``max_frames``, ``duration``, ``interrupted``).
    files : tuple of pathlib.Path
    page : str or None
        With ``options.view``: the live view's page
        (:func:`~reflector_opt.report._view3d.live_page`), served while it is written
        (:class:`~reflector_opt.robot._live.LiveView`).
    """

    link: object
    protocol: object
    units: list
    options: object
    link_length_mm: float
    clock: object = time.time
    in_use: list | None = None
    counts: dict | None = None
    files: tuple = ()
    page: str | None = None

    def write(self, output):
        """Stream the link into the angles CSV ``output`` (and the MCAP log) until it ends,
        the bounds are reached or Ctrl-C; returns this run with ``counts`` and ``files``."""
        from reflector_opt.robot._live import LiveView
        from reflector_opt.robot._stream import PreparedUnits, csv_rows, estimate_block

        o, clock = self.options, self.clock
        decoder, prepared = self.protocol.decoder(), PreparedUnits(self.units)
        counts = {"frames": 0, "skipped": 0, "max_backlog": 0, "max_lag_ms": 0.0}
        start, stopped = clock(), "end"
        with ExitStack() as files:
            files.callback(getattr(self.link, "close", lambda: None))
            live = files.enter_context(LiveView(o.view, self.page)) if o.view else None
            handle = files.enter_context(open(output, "wb", buffering=0))
            labels, log = [c.unit for c in self.units], None
            if o.mcap:  # the robot extra's mcap, checked by stream()
                from reflector_opt.robot._mcap import McapLog

                log = files.enter_context(McapLog(o.mcap, labels, self.link_length_mm))
            try:
                for frames in decoder.blocks(self.link):
                    received = clock()
                    counts["max_backlog"] = max(counts["max_backlog"], len(frames))
                    if o.keep_up and len(frames) > o.keep_up:
                        counts["skipped"] += len(frames) - o.keep_up
                        frames = frames[-o.keep_up :]
                    if o.max_frames:
                        frames = frames[: o.max_frames - counts["frames"]]
                    if frames:
                        shape = estimate_block(
                            frames,
                            self.protocol,
                            self.units,
                            noise_v=o.noise_v,
                            link_length_mm=self.link_length_mm,
                            in_use=self.in_use,
                            prepared=prepared,
                        )
                        handle.write(csv_rows(shape, header=counts["frames"] == 0))
                        if log:
                            log.write(shape, round(received * 1e9))
                        if live:
                            live.show(shape)
                        counts["frames"] += len(frames)
                        lag_ms = (clock() - received) * 1e3
                        counts["max_lag_ms"] = max(counts["max_lag_ms"], lag_ms)
                    if o.max_frames and counts["frames"] >= o.max_frames:
                        stopped = "max_frames"
                    elif o.duration_s and clock() - start >= o.duration_s:
                        stopped = "duration"
                    if stopped != "end":
                        break
            except KeyboardInterrupt:
                stopped = "interrupted"
        counts.update(faults=dict(decoder.faults), stopped=stopped)
        written = (Path(output), *([Path(o.mcap)] if o.mcap else []))
        return replace(self, counts=counts, files=written)

    @property
    def interrupted(self):
        """Whether Ctrl-C stopped it."""
        return self.counts["stopped"] == "interrupted"

    def to_dict(self):
        """JSON-ready (``stream --json``); ``sigma_in_use``: what the 1σ holds of the in-use
        terms (None without ``--conditions``)."""
        return {
            **self.counts,
            "units": [c.unit for c in self.units],
            "files": [str(f) for f in self.files],
            "sigma_in_use": self._in_use_note(),
        }

    def _in_use_note(self):
        from reflector_opt.calibration._in_use import in_use_note

        return None if self.in_use is None else in_use_note(self.in_use, self.protocol.temperature)

    def text(self):
        """One line: frames, units, why it stopped, the faults, and whether it kept up (and a
        second on the in-use terms, with ``--conditions``)."""
        c = self.counts
        faults = ", ".join(f"{k} {v}" for k, v in c["faults"].items())
        line = (
            f"{c['frames']} frame(s) × {len(self.units)} unit(s) streamed (stopped: "
            f"{c['stopped']}); faults: {faults}; up to {c['max_backlog']} frame(s) waited at "
            f"once, {c['skipped']} skipped; lag ≤ {c['max_lag_ms']:.3g} ms"
        )
        note = self._in_use_note()
        return line if note is None else f"{line}\n{note}"


#: How a device's frames are read, as ``stream`` and ``record`` take it (docs/robot.md).
FrameForm = option(Literal["binary", "text"], "the frames' form (docs/robot.md)")
FrameTemperature = option(bool, "each frame holds each unit's temperature, °C")
AdcBits = option(
    int,
    "readings as raw codes of an ADC of this many bits; volts if left out",
    metavar="BITS",
    ge=1,
    le=16,
)
AdcReference = option(float, "the ADC's reference, V", metavar="V", gt=0, le=50)
Baud = option(int, "a serial port's rate, Bd", metavar="BD", ge=50, le=4_000_000)


class StreamOptions(Options):
    """The options of ``reflector-opt stream``, declared once."""

    units: (
        option(
            int,
            "units per frame, base first; the calibration's if left out",
            metavar="N",
            ge=1,
            le=64,
        )
        | None
    ) = None
    form: FrameForm = "binary"
    temperature: FrameTemperature = False
    adc_bits: AdcBits | None = None
    adc_reference_v: AdcReference = 3.3
    baud: Baud = 115200
    noise_v: NoiseV = 0.0
    conditions: InUseConditions = None
    design: InUseDesign = None
    link_length_mm: LinkLength | None = None
    mcap: option(str, "also write an MCAP log with ROS 2 schemas", metavar="FILE") | None = None
    max_frames: option(int, "stop after this many frames", metavar="N", ge=1, le=10**12) | None = (
        None
    )
    duration_s: (
        option(
            float,
            "stop after this many seconds (checked as frames arrive)",
            flag="--duration",
            metavar="S",
            gt=0,
            le=1e7,
        )
        | None
    ) = None
    view: (
        option(
            str,
            "show the segment live in a browser at http://HOST:PORT/ (port 0: any free one, "
            "printed); the newest shape only, at most 30 a second",
            metavar="HOST:PORT",
        )
        | None
    ) = None
    keep_up: (
        option(
            int,
            "of the frames that arrived together, estimate only the newest N and count the "
            "others skipped (a stream faster than the estimator); every frame if left out",
            metavar="N",
            ge=1,
            le=10**6,
        )
        | None
    ) = None


@takes(StreamOptions)
def stream(link, coefficients, options=None, *, clock=time.time):
    """A device's frames to live angles: ``reflector-opt stream``; :meth:`StreamRun.write`
    runs it into a CSV (and an MCAP log).

    Parameters
    ----------
    link : str or iterable of bytes
        ``serial:PORT``, ``udp:HOST:PORT``, ``-`` (standard input) or a file, FIFO or
        pseudo-terminal path (:func:`~reflector_opt.robot._protocol.open_link`), or the
        chunks themselves.
    coefficients : str or pathlib.Path
        Written by ``calibrate``; unit j of a frame is its j-th unit.
    options : StreamOptions
        As keyword arguments (below).
    clock : callable
        ``clock()`` → s since the epoch.

    Returns
    -------
    StreamRun

    Raises
    ------
    InputError
        A file or link that cannot be opened, frames with a unit the calibration lacks,
        compensated units without temperatures, ``--conditions`` without a design to judge
        them on, ``--design`` without ``--conditions``; before anything is written.
    """
    from reflector_opt.design._components import Mechanics
    from reflector_opt.design._defaults import as_design
    from reflector_opt.report._view3d import live_page
    from reflector_opt.robot._live import view_address
    from reflector_opt.robot._protocol import Protocol, open_link
    from reflector_opt.robot._stream import streamed_units
    from reflector_opt.workflow._estimate import load_unit_calibrations

    calibrations = load_unit_calibrations(coefficients)
    protocol = Protocol(
        options.units or len(calibrations),
        temperature=options.temperature,
        adc_bits=options.adc_bits,
        adc_reference_v=options.adc_reference_v,
        form=options.form,
    )
    units = streamed_units(protocol, calibrations)
    in_use = in_use_of(units, options, design_read=bool(options.view))
    if options.mcap and importlib.util.find_spec("mcap") is None:
        raise InputError("--mcap: mcap is not installed (pip install 'reflector-opt[robot]')")
    length = options.link_length_mm or Mechanics.link_length_mm
    page = None
    if options.view:
        view_address(options.view)
        if importlib.util.find_spec("websockets") is None:
            raise InputError(
                "--view: websockets is not installed (pip install 'reflector-opt[robot]')"
            )
        design = as_design(options.design)
        page = live_page(design, len(units), length)
    if isinstance(link, str):
        link = open_link(link, baud=options.baud)
    return StreamRun(link, protocol, units, options, length, clock, in_use, page=page)
