"""Time and memory of ``reflector-opt estimate`` on a long voltage log, against a baseline.

Writes coefficients of two simulated units and a voltage log of ``--rows`` rows (the
synthetic validation motion repeated, instants numbered on), then runs the command in a
fresh interpreter for the working tree and for ``--baseline`` (a commit, checked out in a
temporary worktree), alternately, ``--repeat`` times each. Each run reports its wall and
CPU time, the peak resident memory of the whole process (``VmHWM``: ``ru_maxrss`` of a
process started from this one would report this one's memory when it was forked), the peak
after the imports of the command line, before the command runs, and whether the forward
model (numba) or SciPy's optimisers were imported. The outputs of both trees must hold the same
numbers. The targets: the whole process below 200 MB and 5 s on 1,000,000 rows.

The ``temperature`` case (``--cases``) runs the working tree on the same log with a
``temperature_c`` column, with temperature-compensated coefficients of the same units
(calibrated at 25 and 35 °C), and reports its time and memory against the plain case's.

    python benchmarks/bench_estimate.py --rows 1000000 --baseline b7a0867
    python benchmarks/bench_estimate.py --rows 1000000 --cases plain,temperature

Figures and their load average are recorded in docs/performance-calibration.md.
"""

import argparse
import csv
import json
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from baseline import ROOT, checkout, run_script

TIMING = """
import json, resource, sys, time
from pathlib import Path
import reflector_opt
from reflector_opt.cli import main

def cpu_s():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime

def peak_mb():
    status = Path("/proc/self/status").read_text().splitlines()
    return next(int(line.split()[1]) for line in status if line.startswith("VmHWM:")) / 1024

coefficients, log, output = sys.argv[1:4]
imported = peak_mb()
start, cpu = time.perf_counter(), cpu_s()
code = main(["estimate", coefficients, log, "-o", output])
seconds, cpu = time.perf_counter() - start, cpu_s() - cpu
heavy = sorted(m for m in ("numba", "scipy.optimize", "pandas") if m in sys.modules)
print(json.dumps({"package": reflector_opt.__file__, "code": code, "seconds": seconds,
                  "cpu_s": cpu, "imports_mb": imported, "peak_mb": peak_mb(), "heavy": heavy}))
"""

#: The targets of the whole process on 1,000,000 rows.
TARGET_MB, TARGET_S = 200, 5.0


def _compensated(folder, design, units, data):
    """Temperature-compensated coefficients of the units: ``data`` at 25 °C, and the same
    poses at 35 °C through the light path of model.temperature (generic coefficients)."""
    from reflector_opt.calibration._files import write_calibration_csv
    from reflector_opt.calibration._simulation import measure_with_design_noise
    from reflector_opt.calibration._unit_calibration import calibrate_csv, save_calibrations
    from reflector_opt.model._forward import voltages
    from reflector_opt.model._operating import OperatingState, apply_state

    rng = np.random.default_rng(4)
    labels, angles = np.asarray(data["unit"]), np.asarray(data["angles_deg"])
    warm = np.empty_like(np.asarray(data["volts"]))
    for j, mismatch in enumerate(units):
        rows = labels == str(j + 1)
        clean = voltages(design, angles[rows, 0], angles[rows, 1])
        hot = apply_state(clean, design.models, OperatingState(delta_t_k=10.0))
        warm[rows] = measure_with_design_noise(design, mismatch.apply(hot), rng)
    n = len(labels)
    write_calibration_csv(
        folder / "data_t.csv",
        np.r_[labels, labels],
        np.vstack([data["volts"], warm]),
        np.vstack([angles, angles]),
        np.r_[np.full(n, 25.0), np.full(n, 35.0)],
    )
    save_calibrations(folder / "coef_t.json", calibrate_csv(folder / "data_t.csv", folds=0))


def _temperature_log(folder):
    """log.csv with a temperature_c column (25 to 35 °C, slowly varying) as log_t.csv."""
    with (
        open(folder / "log.csv", encoding="utf-8") as source,
        open(folder / "log_t.csv", "w", encoding="utf-8") as handle,
    ):
        handle.write(source.readline().rstrip("\n") + ",temperature_c\n")
        for i, line in enumerate(source):
            handle.write(f"{line.rstrip()},{30.0 + 5.0 * np.sin(i / 5000.0):.2f}\n")


def write_inputs(folder, rows):
    """Coefficients of two simulated units and a voltage log of ``rows`` rows; and the same
    with temperatures (``coef_t.json``, ``log_t.csv``)."""
    from reflector_opt.calibration._files import write_calibration_csv
    from reflector_opt.calibration._synthetic import built_units, calibration_data, voltage_log
    from reflector_opt.calibration._unit_calibration import calibrate_csv, save_calibrations
    from reflector_opt.design import default_design

    design = default_design()
    units = built_units(design, seed=3)[:2]
    data = calibration_data(design, units, step_deg=3.0, seed=1)
    write_calibration_csv(folder / "data.csv", data["unit"], data["volts"], data["angles_deg"])
    save_calibrations(folder / "coef.json", calibrate_csv(folder / "data.csv", folds=0))
    motion = voltage_log(design, units, "pitch", cycles=1, samples_per_cycle=500, seed=2)
    labels, volts = np.asarray(motion["unit"]), np.asarray(motion["volts"])
    per_pass = len(labels)
    instants_per_pass = per_pass // 2
    with open(folder / "log.csv", "w", encoding="utf-8") as handle:
        handle.write("sample,unit,v1,v2\n")
        for start in range(0, rows, per_pass):
            n = min(per_pass, rows - start)
            sample = start // 2 + np.arange(n) // 2
            lines = [
                f"{s},{u},{v[0]!r},{v[1]!r}\n"
                for s, u, v in zip(sample, labels[:n], volts[:n].tolist(), strict=True)
            ]
            handle.writelines(lines)
    assert per_pass == 2 * instants_per_pass
    _compensated(folder, design, units, data)
    _temperature_log(folder)
    return folder / "coef.json", folder / "log.csv"


def _numbers(path):
    with open(path, newline="", encoding="utf-8") as handle:
        rows = list(csv.reader(handle))
    return rows[0], np.array([[float(x) for x in row[1:]] for row in rows[1:]])


def _runs(folder, trees, cases, repeat):
    """Every run's result by name: ``new`` and ``baseline`` on the plain log, ``temperature``
    (the working tree) on the log with temperatures; alternately, ``repeat`` times each."""
    inputs = {
        "new": (ROOT, folder / "coef.json", folder / "log.csv"),
        "baseline": (trees.get("baseline"), folder / "coef.json", folder / "log.csv"),
        "temperature": (ROOT, folder / "coef_t.json", folder / "log_t.csv"),
    }
    wanted = [n for n in inputs if inputs[n][0] is not None and (n == "baseline" or n in cases)]
    results = {name: [] for name in wanted}
    for _ in range(repeat):
        for name in wanted:
            tree, coefficients, log = inputs[name]
            out = folder / f"angles-{name}.csv"
            result = run_script(tree, TIMING, coefficients, log, out)
            assert result["code"] == 0, result
            results[name].append(result)
    return results


def _median_ratio(results, over, under, key):
    return np.median([r[key] for r in results[over]]) / np.median([r[key] for r in results[under]])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=1_000_000)
    parser.add_argument("--baseline", default=None, help="commit to compare with")
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--cases", default="plain", help="plain, temperature or both (comma)")
    args = parser.parse_args()
    cases = {"new" if c == "plain" else c for c in args.cases.split(",")}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        write_inputs(folder, args.rows)
        with checkout(args.baseline) if args.baseline else _nothing() as base:
            results = _runs(folder, {} if base is None else {"baseline": base}, cases, args.repeat)
            if base is not None:
                head_new, new = _numbers(folder / "angles-new.csv")
                head_old, old = _numbers(folder / "angles-baseline.csv")
                assert head_new == head_old and np.array_equal(new, old)
    load = os.getloadavg()
    print(f"{args.rows:,} rows; load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f}")
    for name, runs in results.items():
        for r in runs:
            print(
                f"  {name:<11} {r['seconds']:6.2f} s (CPU {r['cpu_s']:4.2f} s)   "
                f"peak {r['peak_mb']:6.0f} MB   "
                f"after imports {r['imports_mb']:5.0f} MB   estimate "
                f"{r['peak_mb'] - r['imports_mb']:5.0f} MB   imported {', '.join(r['heavy'])}"
            )
    ours = [r for name in ("new", "temperature") for r in results.get(name, [])]
    worst = max(r["peak_mb"] for r in ours), max(r["seconds"] for r in ours)
    met = worst[0] < TARGET_MB and worst[1] < TARGET_S
    print(
        f"  working tree, worst run: {worst[0]:.0f} MB, {worst[1]:.2f} s "
        f"(target < {TARGET_MB} MB and < {TARGET_S:g} s: {'met' if met else 'NOT met'})"
    )
    if "baseline" in results and "new" in results:
        ratio = _median_ratio(results, "baseline", "new", "seconds")
        print(f"  speed-up (median baseline / median new): {ratio:.1f}x")
    if "temperature" in results and "new" in results:
        print(
            "  temperature_c column and compensation / plain (medians): "
            + ", ".join(
                f"{label} {_median_ratio(results, 'temperature', 'new', key):.2f}x"
                for label, key in (("time", "seconds"), ("CPU", "cpu_s"), ("peak", "peak_mb"))
            )
        )
    print(json.dumps(results))


class _nothing:
    def __enter__(self):
        return None

    def __exit__(self, *exc):
        return False


if __name__ == "__main__":
    main()
