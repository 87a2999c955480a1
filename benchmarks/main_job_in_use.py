"""The main job in use: what README's main command designs, against the default design and the
white-noise optimum, and what the in-use objective costs.

    python benchmarks/main_job_in_use.py

Runs, in one process on one worker, seed 0:

1. one white-noise search and one in-use search in the default conditions (``Conditions()``,
   the stated ``dc`` read-out), their wall times and ratio;
2. README's main command as a run (``reflector_opt.optimise_run``, default options: in use,
   read-out chosen) and the same with ``objective="resolution"``, each with its report and
   parts, their wall times and ratio;
3. for the default conditions and for examples/conditions.toml: the design the run writes
   (geometry, drive and calibration chosen together) against the white-noise optimum read as
   stated (``dc``, uncompensated) and the default design as stated — worst case in use, median,
   white-noise floor, the read-out chosen; and the worst cases with the angle reference's zero
   stated 0 (what the assumed reference class hides).

The figures of docs/optimiser.md, "The main job in use (measured)".
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from reflector_opt.analysis._budget import error_budget
from reflector_opt.design._conditions import Conditions, load_conditions
from reflector_opt.optimiser import Problem, optimise
from reflector_opt.optimiser._search import SearchBudget
from reflector_opt.workflow import OptimiseOptions, optimise_run

ROOT = Path(__file__).resolve().parents[1]


def _timed(call, *args, **kwargs):
    start = time.perf_counter()
    value = call(*args, **kwargs)
    return value, time.perf_counter() - start


def _run(folder, name, **options):
    return _timed(optimise_run, OptimiseOptions(workers=1, **options), out=Path(folder) / name)


def _row(name, run):
    block = run.design.predicted["conditions"]
    r = run.design.predicted["metrics"]["resolution_deg"]
    floor = max(v for v in (r["pitch_worst"], r["roll_worst"]) if v is not None)
    chosen = block.get("read_out", {}).get("chosen")
    read_out = block["conditions"] if chosen is None else chosen
    zero = block["conditions"] | {"reference_zero_deg": [0.0, 0.0]}
    stated_zero = error_budget(run.design, Conditions(**zero)).worst_case_deg
    print(
        f"{name} | worst {block['worst_case_deg']:.3f}° | median {block['median_deg']:.3f}° | "
        f"floor {floor:.4f}° | {read_out['drive']} at {read_out['sample_rate_hz']:g} Sa/s, "
        f"compensated {read_out['temperature_compensated']} | reference zero 0: "
        f"{stated_zero:.3f}°"
    )
    return block


def main():
    budget = SearchBudget(workers=1)
    _, t_white = _timed(optimise, Problem(), seed=0, budget=budget)
    _, t_in_use = _timed(optimise, Problem(conditions=Conditions()), seed=0, budget=budget)
    print(
        f"one search: white-noise {t_white:.1f} s, in use {t_in_use:.1f} s, "
        f"ratio {t_in_use / t_white:.2f}"
    )
    with tempfile.TemporaryDirectory() as folder:
        before, t_before = _run(folder, "before", objective="resolution")
        after, t_after = _run(folder, "after")
        print(
            f"README's main command: white-noise objective {t_before:.1f} s, in use "
            f"{t_after:.1f} s, ratio {t_after / t_before:.2f}"
        )
        for label, conditions in (
            ("default conditions", None),
            ("examples/conditions.toml", ROOT / "examples" / "conditions.toml"),
        ):
            if conditions is None:
                white, written = before, after
            else:
                white, _ = _run(
                    folder,
                    "white",
                    objective="resolution",
                    read_out="stated",
                    conditions=conditions,
                    report=False,
                )
                written, _ = _run(folder, "written", conditions=conditions, report=False)
            stated = Conditions() if conditions is None else load_conditions(conditions)
            print(f"{label}:")
            block = _row("  written (geometry, drive, calibration)", written)
            white_block = _row("  white-noise optimum", white)
            base = block["baseline"]
            print(
                f"  default design as stated | worst {base['worst_case_deg']:.3f}° | median "
                f"{base['median_deg']:.3f}° | improvement {block['improvement']:.2f}× worst, "
                f"{block['improvement_median']:.2f}× median | against the white-noise optimum "
                f"({stated.drive}, compensated {stated.temperature_compensated}): "
                f"{white_block['worst_case_deg'] / block['worst_case_deg']:.2f}×"
            )


if __name__ == "__main__":
    main()
