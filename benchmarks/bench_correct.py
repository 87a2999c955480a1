"""Benchmark: the work ``correct`` does to choose its step and write the parts.

Run from the repository root:

    PYTHONPATH=. python benchmarks/bench_correct.py [--cut-back]

The batch is tests/asbuilt/printloop.py's "strong" one (4 units, exact optics, 49-pose grid,
the seed whose batch the step search corrects; ``model_form`` none, no prediction, no
pictures). With ``--cut-back`` a stand-in limit in export's checks refuses every design whose
sphere centre lies more than 3.66 µm below y = 0 (the drawings beyond about step 0.3), so that
the step is cut back by bisection. Printed: the step and what was given up, the solids built
(:func:`reflector_opt.cad._solids.build_parts` calls: one per export or in-memory check),
temporary folders made, expected-loss evaluations, ``corrected_design`` calls, and the CPU
time (this process and its children) and wall time of ``correct``. Counts do not depend
on the machine's load; the times do (docs/print-loop.md).
"""

from __future__ import annotations

import argparse
import json
import resource
import tempfile
import time
from pathlib import Path

from reflector_opt.asbuilt import _correction as correction
from reflector_opt.asbuilt import _stepsearch as stepsearch
from reflector_opt.asbuilt._asbuiltfile import identification_to_dict
from reflector_opt.cad import _export as export
from reflector_opt.util._errors import InputError
from reflector_opt.workflow import correct
from tests.asbuilt.printloop import CORRECTED_SEED, printed

COUNTS = {"solids built": 0, "temporary folders": 0, "losses": 0, "corrected_design": 0}


def counted(module, name, key):
    """Count the calls of ``module.name``."""
    call = getattr(module, name)

    def wrapper(*args, **kwargs):
        COUNTS[key] += 1
        return call(*args, **kwargs)

    setattr(module, name, wrapper)


def limit_centre_y(check):
    """export's checks, refusing a design whose sphere centre is below y = −3.66 µm."""

    def limited(design, *args, **kwargs):
        if design.reflector.centre_mm[1] < -0.00366:
            raise InputError("reflector: a stand-in wall below the printable minimum")
        return check(design, *args, **kwargs)

    return limited


def cpu_s():
    return sum(
        getattr(resource.getrusage(who), field)
        for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)
        for field in ("ru_utime", "ru_stime")
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cut-back", action="store_true", help="a stand-in limit at step 0.3")
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp())
    _, result = printed("strong", seed=CORRECTED_SEED)
    as_built = folder / "AS_BUILT.json"
    as_built.write_text(json.dumps(identification_to_dict(result, "cal.csv", batch="B1")))
    counted(export, "build_parts", "solids built")
    counted(stepsearch, "expected_loss", "losses")
    counted(correction, "corrected_design", "corrected_design")
    counted(tempfile, "mkdtemp", "temporary folders")  # TemporaryDirectory makes one with it
    if args.cut_back:
        export._check = limit_centre_y(export._check)
    cpu, wall = cpu_s(), time.perf_counter()
    run = correct(as_built, model_form="none", predict=False, preview=False).write(folder / "next")
    cpu, wall = cpu_s() - cpu, time.perf_counter() - wall
    print(f"step {run.correction.step:.6g}; given up: {'; '.join(run.correction.given_up)}")
    print(", ".join(f"{key} {value}" for key, value in COUNTS.items()))
    print(f"correct: {cpu:.1f} s CPU, {wall:.1f} s wall")


if __name__ == "__main__":
    main()
