"""A calibration run live, as ``reflector-opt record`` makes it
(:mod:`reflector_opt.robot._record`)."""

import time
from dataclasses import dataclass, replace
from pathlib import Path

from reflector_opt.util._declared import Options, option, takes
from reflector_opt.util._display import Printed
from reflector_opt.workflow._stream import AdcBits, AdcReference, Baud, FrameForm, FrameTemperature


@dataclass(frozen=True, repr=False)
class RecordRun(Printed):
    """A recorded calibration run (:func:`record`): its samples, coverage and faults.

    Attributes
    ----------
    recorder : reflector_opt.robot._record.Recorder
        Fed to the plan's end or the device's.
    files : tuple of pathlib.Path
        The calibration CSV, once written.
    """

    recorder: object
    files: tuple = ()

    def write(self, output):
        """Write the calibration CSV ``calibrate`` reads, atomically; returns this run with
        ``files``.

        Raises
        ------
        InputError
            No pose kept (nothing is written).
        """
        from reflector_opt.calibration._files import write_calibration_csv
        from reflector_opt.util._errors import InputError

        rows = self.recorder.rows
        if not rows:
            raise InputError(f"record: no pose kept ({self._faults()}); nothing written")
        units, v1, v2, pitch, roll, temps = zip(*rows, strict=True)
        temps = None if temps[0] is None else temps
        write_calibration_csv(
            output,
            units,
            list(zip(v1, v2, strict=True)),
            list(zip(pitch, roll, strict=True)),
            temps,
        )
        return replace(self, files=(Path(output),))

    def _faults(self):
        return ", ".join(f"{k} {v}" for k, v in self.recorder.faults.items() if v) or "no faults"

    def to_dict(self):
        """JSON-ready (``record --json``)."""
        r = self.recorder
        return {
            "poses": len(r.poses_deg),
            "kept": [k + 1 for k, _, _ in r.kept],
            "largest_std_v": max((s for _, s, _ in r.kept), default=None),
            "largest_reference_deviation_deg": max((d for _, _, d in r.kept), default=None),
            "faults": r.faults,
            "clock_offset_s": r.offset_s,
            "largest_reference_lag_s": r.max_lag_s,
            "output": str(self.files[0]) if self.files else None,
        }

    def text(self):
        """The coverage and quality, the clocks and the faults."""
        from reflector_opt.robot._record import coverage_line

        r = self.recorder
        offset = "no reference sample" if r.offset_s is None else f"{r.offset_s:.3f} s"
        return "\n".join(
            [
                coverage_line(r),
                f"reference clock offset {offset}, largest lag beyond it {r.max_lag_s:.3f} s",
                f"faults: {self._faults()}",
            ]
        )


class RecordOptions(Options):
    """The options of ``reflector-opt record``, declared once."""

    units: option(
        int, "units per frame, base first, labelled 1, 2, …", metavar="N", ge=1, le=64
    ) = 1
    temperature: FrameTemperature = False
    adc_bits: AdcBits | None = None
    adc_reference_v: AdcReference = 3.3
    form: FrameForm = "binary"
    baud: Baud = 115200
    window_s: option(float, "settling window, s", metavar="S", flag="--window", gt=0, le=60) = 0.5
    spread_mv: option(
        float,
        "largest standard deviation of a reading in the window, mV",
        metavar="MV",
        gt=0,
        le=1000,
    ) = 1.0
    tolerance_deg: option(
        float,
        "the reference within this of the pose, in pitch and roll, degrees",
        metavar="DEG",
        flag="--tolerance",
        gt=0,
        le=10,
    ) = 0.5
    timeout_s: option(
        float,
        "a pose not taken within this is missed, s",
        metavar="S",
        flag="--timeout",
        gt=0,
        le=3600,
    ) = 30.0
    stop_s: option(
        float,
        "a reference silent this long has stopped, s",
        metavar="S",
        flag="--stop-after",
        gt=0,
        le=3600,
    ) = 1.0
    late_s: option(
        float,
        "a reference sample this much later than the best is late, s",
        metavar="S",
        flag="--late-after",
        gt=0,
        le=3600,
    ) = 0.2


@takes(RecordOptions)
def record(plan, device, reference, options=None, progress=None, clock=time.monotonic):
    """Record a calibration live: ``reflector-opt record``.

    Parameters
    ----------
    plan : str or pathlib.Path
        ``plan.csv`` of ``plan-calibration``.
    device, reference : str
        Their links (:func:`~reflector_opt.robot._protocol.open_link`): the device's frames,
        the reference's lines ``time_s,unit,pitch_deg,roll_deg``.
    options : RecordOptions
        As keyword arguments (below).
    progress : callable, optional
        ``progress(fraction, message)``: the next pose, each pose's outcome, the coverage.
    clock : callable
        ``clock()`` → s, the run's time.

    Returns
    -------
    RecordRun

    Raises
    ------
    InputError
        A plan that cannot be read, a link that cannot be opened.
    """
    from reflector_opt.calibration._files import read_plan_csv
    from reflector_opt.robot import Protocol
    from reflector_opt.robot._protocol import open_link
    from reflector_opt.robot._record import Recorder, merged
    from reflector_opt.robot._record import record as run

    poses, _ = read_plan_csv(plan)
    o = options
    protocol = Protocol(o.units, 2, o.temperature, o.adc_bits, o.adc_reference_v, o.form)
    recorder = Recorder(
        protocol,
        poses,
        o.window_s,
        o.spread_mv / 1e3,
        o.tolerance_deg,
        o.timeout_s,
        o.stop_s,
        o.late_s,
        progress,
    )
    links = {
        name: open_link(a, baud=o.baud)
        for name, a in (("device", device), ("reference", reference))
    }
    return RecordRun(run(merged(links, clock), recorder))
