"""Benchmark: ``plan-calibration`` and ``tolerance --samples 1000`` end to end, against a
baseline checkout, with the same results.

Run from the repository root:

    python benchmarks/bench_commands.py --baseline /path/to/old/checkout [--repeats 1]
        [--only plan-calibration|tolerance]

Each command runs as a new process (``python -m reflector_opt … -q``) on the built-in design
with its defaults, the current code and the baseline's (``PYTHONPATH`` set to the baseline
checkout) one after the other, repeated. Printed per run: the wall time, the CPU time of the
process and its workers (user + system, from ``getrusage(RUSAGE_CHILDREN)``) and the load
average before it; then the ratios baseline / current of the medians, and how far the results
differ: for plan-calibration the largest difference of a predicted RMS error (degrees) and
whether the recommendation is the same; for tolerance the largest difference of the yields,
the distribution figures and the Sobol indices, beside the indices' own 95 % intervals.

The cores are shared with other work: the CPU times and the ratios measured in one run are
the figures to quote; wall times hold only with the load average beside them.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

COMMANDS = {
    "plan-calibration": (["plan-calibration"], "plan.json"),
    "tolerance": (["tolerance", "{design}", "--samples", "1000"], "summary.json"),
}


def _children_cpu_s():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run(argv, code, out, design):
    """One run: (wall s, CPU s, load average before, the command's JSON summary)."""
    env = dict(os.environ)
    if code is not None:
        env["PYTHONPATH"] = str(code)
    args = [a.format(design=design) for a in argv]
    load = os.getloadavg()[0]
    cpu, start = _children_cpu_s(), time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "reflector_opt", *args, "-q", "-o", str(out)],
        env=env,
        cwd=tempfile.gettempdir(),  # not the repository: PYTHONPATH alone picks the code
        check=True,
        stdout=subprocess.DEVNULL,
    )
    return time.perf_counter() - start, _children_cpu_s() - cpu, load


def compare_plans(old, new):
    """Largest |Δ RMS| of a prediction (degrees) and whether the recommendation is the same."""
    key = lambda p: (p["pattern"], p["n_poses"], p["form"])  # noqa: E731
    before = {key(p): p for p in old["predictions"]}
    diff = max(
        abs(p["rms_deg"][a] - before[key(p)]["rms_deg"][a])
        for p in new["predictions"]
        for a in ("pitch", "roll")
    )
    same = {key(p) for p in new["predictions"]} == set(before)
    pick = lambda s: s["recommended"] and key(s["recommended"])  # noqa: E731
    same_pick = pick(old) == pick(new)
    return f"largest |Δ RMS| {diff:.2e}°, same plans {same}, same recommendation {same_pick}"


def compare_studies(old, new):
    """Largest differences of the yields, the distributions and the Sobol indices."""
    yields = max(abs(old["yield"][k] - new["yield"][k]) for k in ("all", "window"))
    figures = max(
        abs(old["distributions"][k][s] - new["distributions"][k][s])
        for k in new["distributions"]
        if new["distributions"][k]
        for s in ("median", "p95")
    )
    sobol = max(
        abs(g[i] - h[i])
        for g, h in zip(old["sobol"]["groups"], new["sobol"]["groups"], strict=True)
        for i in ("first", "total")
        if g[i] is not None and h[i] is not None
    )
    widths = [
        g["total_ci"][1] - g["total_ci"][0]
        for g in new["sobol"]["groups"]
        if None not in g["total_ci"]
    ]
    return (
        f"largest |Δ yield| {yields:.2e}, |Δ distribution figure| {figures:.2e}, "
        f"|Δ Sobol index| {sobol:.2e} (total indices' 95 % intervals {min(widths):.3f}–"
        f"{max(widths):.3f} wide)"
    )


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--baseline", type=Path, required=True, help="the old checkout")
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--only", choices=list(COMMANDS))
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        design = folder / "design.json"
        subprocess.run(
            [
                sys.executable,
                "-c",
                f"import reflector_opt as r; r.default_design().save({str(design)!r})",
            ],
            check=True,
        )
        for name, (argv, summary) in COMMANDS.items():
            if args.only and name != args.only:
                continue
            times = {"baseline": [], "current": []}
            results = {}
            for repeat in range(args.repeats):
                for label, code in (("baseline", args.baseline), ("current", ROOT)):
                    out = folder / f"{name}-{label}-{repeat}"
                    wall, cpu, load = run(argv, code, out, design)
                    times[label].append((wall, cpu))
                    results[label] = json.loads((out / summary).read_text())
                    print(
                        f"{name:<17}{label:<9} wall {wall:6.1f} s  CPU {cpu:6.1f} s  "
                        f"(load average {load:.2f} before)",
                        flush=True,
                    )
            med = {
                k: [statistics.median(t[i] for t in v) for i in (0, 1)] for k, v in times.items()
            }
            print(
                f"{name}: baseline / current, wall {med['baseline'][0] / med['current'][0]:.2f}×, "
                f"CPU {med['baseline'][1] / med['current'][1]:.2f}×"
            )
            compare = compare_plans if name == "plan-calibration" else compare_studies
            print(f"{name}: {compare(results['baseline'], results['current'])}")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
