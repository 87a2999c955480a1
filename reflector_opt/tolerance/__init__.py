"""Tolerance analysis: what fraction of built units meets the targets, and which tolerance
drives the error (docs/tolerance.md).

* :mod:`~reflector_opt.tolerance.model` — distributions of the manufacturing and operating
  errors, per-sample draws, the as-built unit;
* :mod:`~reflector_opt.tolerance.analysis` — calibrate and assess one as-built unit;
* :mod:`~reflector_opt.tolerance.sensitivity` — Sobol indices and their bootstrap intervals
  (:func:`scipy.stats.sobol_indices` on the pick-and-freeze sample);
* :mod:`~reflector_opt.tolerance.study` — the Monte Carlo study, yield, sensitivity ranking;
* :mod:`~reflector_opt.tolerance.sweep` — nominal performance and yield over a grid of designs;
* :mod:`~reflector_opt.tolerance.output` — results CSV, summary JSON, figures;
* :mod:`~reflector_opt.tolerance.truth` — built-unit truth: calibration data from the exact
  optics of a unit drawn from the tolerance model;
* :mod:`~reflector_opt.tolerance.prediction` — a design's windows and predicted calibration
  errors against that truth;
* :mod:`~reflector_opt.tolerance.planning` — predicted error against the calibration plan's
  size and pattern, per form, and the recommended plan.

The executors the studies run on (local processes, a Dask cluster) are the package's shared
worker pools, :mod:`~reflector_opt.util.pools` and :mod:`~reflector_opt.util.dask_pool`,
re-exported here.
"""

from reflector_opt.util.lazy import lazy_exports

#: Each public name and the module that defines it, imported on first use.
_SOURCES = {
    "Draw": "reflector_opt.tolerance.model",
    "Job": "reflector_opt.tolerance.analysis",
    "Settings": "reflector_opt.tolerance.analysis",
    "Spread": "reflector_opt.tolerance.model",
    "Targets": "reflector_opt.tolerance.analysis",
    "ToleranceStudy": "reflector_opt.tolerance.study",
    "Tolerances": "reflector_opt.tolerance.model",
    "as_built": "reflector_opt.tolerance.model",
    "dask_cluster": "reflector_opt.util.dask_pool",
    "draw_sample": "reflector_opt.tolerance.model",
    "evaluate_draw": "reflector_opt.tolerance.analysis",
    "local_processes": "reflector_opt.util.pools",
    "reused": "reflector_opt.util.pools",
    "run_batches": "reflector_opt.util.pools",
    "run_study": "reflector_opt.tolerance.study",
    "sobol_indices": "reflector_opt.tolerance.sensitivity",
    "supplied": "reflector_opt.util.pools",
}

__all__ = list(_SOURCES)
__getattr__, __dir__ = lazy_exports(__name__, _SOURCES)
