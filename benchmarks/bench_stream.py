"""Live rate and latency of ``reflector-opt stream``: 4 units, one frame per read, into the
angles CSV and the MCAP log on disk, against a baseline.

A pre-encoded frame source (binary frames of four built units of the sample design, the
forward model's readings along a bending trajectory, each unit's gain and offset) feeds the
real path (:func:`reflector_opt.workflow._stream.stream` and ``StreamRun.write``: decoder,
estimate, CSV, MCAP, both files on disk), with ``--noise-v`` so that every frame's σ needs
its Jacobian. Two runs per case:

* **paced**: a device process sends the frames at ``--rate`` (slept to), one ``write`` each,
  into a pipe that ``stream`` reads as its link (``open_link``, the kernel waking it as a
  frame arrives: a live link's path). A frame's latency is from just before its write to
  the moment the loop asks for its next read, the block that held it written to both files
  (a loop that falls behind reads several frames at once and shows it in the latency);
* **unpaced**: the frames one per read, handed over as fast as the loop takes them: the
  most it sustains (frames/s) and the per-frame cost.

The cases: ``poly3`` (a cubic polynomial per unit) and ``thermal`` (the same, temperature
compensated: calibrated on readings at 25 and 35 °C made with Eq (1) of
reflector_opt.calibration._temperature, c = −0.5 %/K and d = 0.1 mV/K, assumed figures that
only the speed depends on, not the result). Each run also times a fixed reference (small
numpy operations, the per-frame path's kind of work) so that its cost can be read as a
ratio on a shared, loaded machine, and reports the load average. The top items of a cProfile
of an unpaced run say what limits it (cProfile inflates Python-level calls). With
``--baseline COMMIT`` the same runs are made on that commit's package (a temporary
``git worktree``), alternately (its paced run one second at most: it falls behind). The
stages of one frame (decode, estimate, CSV, MCAP), each timed alone, best of 7 rounds, say
what limits it too, with what the MCAP writer costs for two records in a chunk of their own
(a block's chunk, flushed) against the same records written outside chunks.

    python benchmarks/bench_stream.py --rate 2000 --seconds 5 --baseline ad8047b

Figures are recorded in docs/robot.md ("How fast") and docs/performance.md.
"""

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from baseline import ROOT, checkout, run_script

TIMING = r"""
import cProfile, json, os, pstats, subprocess, sys, tempfile, time
from pathlib import Path

import numpy as np

import reflector_opt
from reflector_opt.calibration import Polynomial, TemperatureCompensated, built_units
from reflector_opt.calibration._unit_calibration import UnitCalibration, save_calibrations
from reflector_opt.design import load_design
from reflector_opt.model._forward import voltages
from reflector_opt.robot import Protocol
from reflector_opt.robot._protocol import Frame, open_link
from reflector_opt.workflow._stream import stream

case, rate, seconds, n_units, noise_v, profiled, fifo = sys.argv[1:8]
rate, seconds, n_units, noise_v = float(rate), float(seconds), int(n_units), float(noise_v)
thermal, n = case == "thermal", max(int(rate * seconds), 2)
design = load_design("examples/data/design.json")
built = built_units(design, n_units, seed=1)
gain, offset = np.array([u.gain for u in built]), np.array([u.offset_v for u in built])

def readings(pitch, roll, delta_k=0.0):
    # Each unit's readings, V, shape (n, units, 2); Eq (1) of the compensation at delta_k.
    v = gain * voltages(design, pitch, roll)[:, None] + offset
    return 3.3 - (3.3 - v) * (1 - 0.005 * delta_k) - 1e-4 * delta_k

grid = np.array([(p, r) for p in np.linspace(-15, 15, 13) for r in np.linspace(-15, 15, 13)])
cold, warm = readings(*grid.T), readings(*grid.T, 10.0)
calibrations = []
for j in range(n_units):
    if thermal:
        model = TemperatureCompensated("poly3").fit(
            np.concatenate([cold[:, j], warm[:, j]]), np.tile(grid, (2, 1)),
            np.repeat([25.0, 35.0], len(grid)))
    else:
        model = Polynomial(3).fit(cold[:, j], grid)
    calibrations.append(UnitCalibration(str(j + 1), model))
folder = Path(tempfile.mkdtemp())
save_calibrations(folder / "coefficients.json", calibrations)
t = np.arange(n) / rate
volts = readings(10 * np.sin(np.pi * t), np.full(n, 5.0), 2.0 if thermal else 0.0)
protocol = Protocol(n_units, temperature=thermal)
temps = np.full(n_units, 27.0) if thermal else None
chunks = [protocol.encode(Frame(k % 65536, volts[k], temps)) for k in range(n)]

def reference_us(rounds=7, number=2000):
    # A fixed computation of the per-frame path's kind: 20 numpy operations on 8 numbers.
    a = np.linspace(0.1, 0.9, 8)
    def work():
        x = a
        for _ in range(10):
            x = np.sqrt(x * x + a)
    best = min(timeit_(work, number) for _ in range(rounds))
    return best / number * 1e6

def timeit_(f, number):
    start = time.perf_counter()
    for _ in range(number):
        f()
    return time.perf_counter() - start

SENDER = '''
import os, sys, time
import numpy as np
path, size, rate, fd, out = sys.argv[1:]
data, size, rate, fd = open(path, "rb").read(), int(size), float(rate), int(fd)
sent = np.empty(len(data) // size)
start = time.perf_counter() + 0.5  # the stream set up and reading by then
for k in range(len(sent)):
    due = start + k / rate
    if (now := time.perf_counter()) < due:
        time.sleep(due - now)
    sent[k] = time.perf_counter()
    os.write(fd, data[k * size : (k + 1) * size])
os.close(fd)
np.save(out, sent)
'''

def watched(link, size, done, ends):
    # The link's chunks; when the loop asks for the next, the frames so far are written.
    total = 0
    for chunk in link:
        total += len(chunk)
        yield chunk
        done.append(time.perf_counter())
        ends.append(total // size)

def run(paced, name):
    # paced: a device process sends the frames at the rate into a pipe that stream reads (a
    # frame's latency: sent → the block holding it written); unpaced: the frames one a read,
    # as fast as the loop takes them (latency: handed over → written).
    options = dict(noise_v=noise_v, mcap=str(folder / f"{name}.mcap"), temperature=thermal)
    size, done, ends = len(chunks[0]), [], []
    if paced:
        (folder / "frames.bin").write_bytes(b"".join(chunks))
        read_end, write_end = os.pipe()
        args = [folder / "frames.bin", size, rate, write_end, folder / "sent.npy"]
        device = subprocess.Popen([sys.executable, "-c", SENDER, *map(str, args)],
                                  pass_fds=[write_end])
        os.close(write_end)
        link = open_link(f"/dev/fd/{read_end}")
    else:
        sent = []
        def link_():
            for chunk in chunks:
                sent.append(time.perf_counter())
                yield chunk
        link = link_()
    written = stream(watched(link, size, done, ends), folder / "coefficients.json", **options)
    if name == "profiled":
        profile = cProfile.Profile()
        profile.enable()
    written = written.write(folder / f"{name}.csv")
    if name == "profiled":
        profile.disable()
        top = sorted(pstats.Stats(profile).stats.items(), key=lambda kv: -kv[1][2])[:12]
        return [(f"{Path(f).parent.name}/{Path(f).name}:{line}({fn})", tt / n * 1e6)
                for (f, line, fn), (cc, nc, tt, ct, callers) in top]
    if paced:
        device.wait()
        os.close(read_end)
        sent = np.load(folder / "sent.npy")
    # frame k is written when the first block whose end is past it is
    written_at = np.repeat(done, np.diff(ends, prepend=0))
    latency = (written_at - np.asarray(sent)) * 1e3
    span = done[-1] - sent[0]
    rows = sum(1 for _ in open(folder / f"{name}.csv")) - 1
    p50, p99 = np.percentile(latency, [50, 99])
    return {"frames": written.counts["frames"], "rows": rows,
            "rate": (n - 1) / (sent[-1] - sent[0]) if paced else n / span,
            "max_backlog": written.counts["max_backlog"], "p50_ms": p50, "p99_ms": p99,
            "max_ms": float(latency.max()), "over_1ms": float(np.mean(latency > 1.0)),
            "mean_cost_us": span / n * 1e6, "mcap_bytes": os.path.getsize(folder / f"{name}.mcap")}

def stages_us(number=500, rounds=7):
    # Each stage of one frame's path, best of rounds, µs: what limits the loop.
    import io
    from mcap.writer import CompressionType, Writer
    from reflector_opt.robot._mcap import McapLog
    from reflector_opt.robot._stream import (
        PreparedUnits, csv_rows, estimate_block, streamed_units)
    from reflector_opt.calibration._unit_calibration import load_calibrations

    units = streamed_units(protocol, load_calibrations(folder / "coefficients.json"))
    frames = protocol.decoder().feed(chunks[1])
    extra = {"prepared": PreparedUnits(units)}  # the working tree's alone
    shape = estimate_block(frames, protocol, units, noise_v=noise_v, link_length_mm=18.0, **extra)
    log = McapLog(folder / "stages.mcap", [c.unit for c in units], 18.0)
    bare = Writer(open(folder / "bare.mcap", "wb"), compression=CompressionType.NONE,
                  use_chunking=False)
    bare.start(profile="ros2")
    channel = bare.register_channel("/a", "cdr", bare.register_schema("a", "ros2msg", b""))
    message = bytes(400)

    def unchunked():
        bare.add_message(channel, 0, message, 0, 0)
        bare.add_message(channel, 0, message, 0, 0)
        bare.flush()

    ids = [channel for channel, _ in log._messages.values()]

    def chunked():  # the same two messages, a chunk of their own
        for channel in ids:
            log._writer.add_message(channel, 0, message, 0, 0)
        log._writer.flush()

    work = {
        "decode": lambda: protocol.decoder().feed(chunks[1]),
        "estimate": lambda: estimate_block(frames, protocol, units, noise_v=noise_v,
                                           link_length_mm=18.0, **extra),
        "csv": lambda: csv_rows(shape),
        "mcap": lambda: log.write(shape, 10**18),
        "mcap_records_in_a_chunk": chunked,
        "mcap_records_unchunked": unchunked,
    }
    out = {k: min(timeit_(f, number) for _ in range(rounds)) / number * 1e6
           for k, f in work.items()}
    log.close()
    return out

reference = reference_us()
result = {"package": reflector_opt.__file__, "case": case, "reference_us": reference,
          "stages_us": stages_us() if profiled == "1" else None,
          "unpaced": run(False, "unpaced")}
if fifo == "1":  # the stream (and its device) before any other job, as a robot's would run
    os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(10))
result["paced"] = run(True, "paced")
os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
if profiled == "1":
    result["profile"] = run(False, "profiled")
result["reference_after_us"] = reference_us()
result["load"] = os.getloadavg()
print(json.dumps(result))
"""


def measure(tree, case, rate, seconds, units=4, noise_v=5e-4, profiled=False, fifo=False):
    """One case's runs (paced, unpaced, and a profiled one) on the package of ``tree``."""
    args = (case, rate, seconds, units, noise_v, int(profiled), int(fifo))
    return run_script(tree, TIMING, *args, env={"OMP_NUM_THREADS": "1"})


def _line(name, r):
    u, p = r["unpaced"], r["paced"]
    ratio = u["mean_cost_us"] / r["reference_us"]
    return (
        f"| {name} | {u['rate']:,.0f} | {u['mean_cost_us']:.0f} µs ({ratio:.1f}× ref) | "
        f"{p['rate']:,.0f} | {p['p50_ms']:.3f} | {p['p99_ms']:.3f} | {p['max_ms']:.2f} | "
        f"{100 * p['over_1ms']:.2f} % | {r['reference_us']:.1f} µs | "
        f"{' '.join(f'{x:.1f}' for x in r['load'])} |"
    )


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rate", type=float, default=2000.0, help="paced frames/s")
    parser.add_argument("--seconds", type=float, default=5.0, help="of frames per run")
    parser.add_argument("--units", type=int, default=4)
    parser.add_argument("--cases", default="poly3,thermal")
    parser.add_argument("--baseline", help="a commit to compare with")
    parser.add_argument("--repeat", type=int, default=1, help="rounds of each tree")
    parser.add_argument(
        "--fifo",
        action="store_true",
        help="the paced run at real-time priority (SCHED_FIFO 10; root or CAP_SYS_NICE): "
        "its latency without other jobs' time slices",
    )
    args = parser.parse_args(argv)
    print(
        "| case, tree | unpaced frames/s | per frame | paced frames/s | p50 ms | p99 ms | "
        "max ms | > 1 ms | reference | load |\n|---|---|---|---|---|---|---|---|---|---|"
    )
    for case in args.cases.split(","):
        for _ in range(args.repeat):
            now = measure(
                ROOT, case, args.rate, args.seconds, args.units, profiled=True, fifo=args.fifo
            )
            print(_line(f"{case}, working tree", now), flush=True)
            if args.baseline:
                with checkout(args.baseline) as tree:
                    seconds = min(args.seconds, 1.0)
                    before = measure(tree, case, args.rate, seconds, args.units, fifo=args.fifo)
                print(_line(f"{case}, {args.baseline}", before), flush=True)
                ratio = before["unpaced"]["mean_cost_us"] / now["unpaced"]["mean_cost_us"]
                print(f"| {case}: per-frame cost, baseline / working tree | {ratio:.1f}× |")
        stages = ", ".join(f"{k} {v:.1f}" for k, v in now["stages_us"].items())
        print(f"\nStages of one frame ({case}, working tree, µs, best of 7 × 500): {stages}")
        print(f"\nTop of the profile ({case}, working tree, µs a frame, own time under cProfile):")
        for item, us in now["profile"]:
            print(f"    {us:7.1f}  {item}")
        print()


if __name__ == "__main__":
    main()
