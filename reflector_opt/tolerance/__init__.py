"""Tolerance analysis: what fraction of built units meets the targets, and which tolerance
drives the error (docs/tolerance.md).

* :mod:`~reflector_opt.tolerance.model` — distributions of the manufacturing and operating
  errors, per-sample draws, the as-built unit;
* :mod:`~reflector_opt.tolerance.analysis` — calibrate and assess one as-built unit;
* :mod:`~reflector_opt.tolerance.sensitivity` — Sobol indices and their bootstrap intervals
  (:func:`scipy.stats.sobol_indices` on the pick-and-freeze sample);
* :mod:`~reflector_opt.tolerance.executors` — batches on local processes or a Dask cluster;
* :mod:`~reflector_opt.tolerance.study` — the Monte Carlo study, yield, sensitivity ranking;
* :mod:`~reflector_opt.tolerance.sweep` — nominal performance and yield over a grid of designs;
* :mod:`~reflector_opt.tolerance.output` — results CSV, summary JSON, figures;
* :mod:`~reflector_opt.tolerance.truth` — built-unit truth: calibration data from the exact
  optics of a unit drawn from the tolerance model;
* :mod:`~reflector_opt.tolerance.prediction` — a design's windows and predicted calibration
  errors against that truth;
* :mod:`~reflector_opt.tolerance.planning` — predicted error against the calibration plan's
  size and pattern, per form, and the recommended plan.
"""

from reflector_opt.tolerance.analysis import Job, Settings, Targets, evaluate_draw
from reflector_opt.tolerance.executors import (
    dask_cluster,
    local_processes,
    reused,
    run_batches,
    supplied,
)
from reflector_opt.tolerance.model import Draw, Spread, Tolerances, as_built, draw_sample
from reflector_opt.tolerance.sensitivity import sobol_indices
from reflector_opt.tolerance.study import ToleranceStudy, run_study

__all__ = [
    "Draw",
    "Job",
    "Settings",
    "Spread",
    "Targets",
    "ToleranceStudy",
    "Tolerances",
    "as_built",
    "dask_cluster",
    "draw_sample",
    "evaluate_draw",
    "local_processes",
    "reused",
    "run_batches",
    "run_study",
    "sobol_indices",
    "supplied",
]
