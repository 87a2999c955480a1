"""Tolerance analysis: what fraction of built units meets the targets, and which tolerance
drives the error (docs/tolerance.md).

* :mod:`~reflector_opt.tolerance._tolerances` — distributions of the manufacturing and operating
  errors, per-sample draws, the as-built unit;
* :mod:`~reflector_opt.tolerance._analysis` — calibrate and assess one as-built unit;
* :mod:`~reflector_opt.tolerance._sensitivity` — Sobol indices and their bootstrap intervals
  (:func:`scipy.stats.sobol_indices` on the pick-and-freeze sample), and their summary;
* :mod:`~reflector_opt.tolerance._study` — the Monte Carlo study and its sensitivity runs;
* :mod:`~reflector_opt.tolerance._statistics` — the sample's yield and its interval, the
  distributions, the required margin and its confidence bound;
* :mod:`~reflector_opt.tolerance._sweep` — nominal performance and yield over a grid of designs;
* :mod:`~reflector_opt.tolerance._output` — results CSV, summary JSON, figures;
* :mod:`~reflector_opt.tolerance._builtunit` — built-unit truth: calibration data from the exact
  optics of a unit drawn from the tolerance model;
* :mod:`~reflector_opt.tolerance._prediction` — a design's windows and predicted calibration
  errors against that truth;
* :mod:`~reflector_opt.tolerance._planning` — predicted error against the calibration plan's
  size and pattern, per form, and the recommended plan;
* :mod:`~reflector_opt.tolerance._thermalplan` — how many poses at which temperatures a
  temperature-compensated calibration needs, simulated on built units.

The executors the studies run on are the package's shared worker pools,
:mod:`~reflector_opt.util._pools` (local processes) and :mod:`~reflector_opt.util._dask_pool`
(a Dask cluster, ``dask_cluster`` re-exported here).
"""

import lazy_loader

#: The modules that define the public names, and the names each gives; a module is
#: imported the first time one of its names is used.
_MODULES = {
    "_tolerances": ("Draw", "Spread", "Tolerances", "as_built", "draw_sample"),
    "_analysis": ("Job", "Settings", "Targets", "evaluate_draw"),
    "_study": ("ToleranceStudy", "run_study"),
    "_sensitivity": ("sobol_indices",),
}

# lazy_loader attaches a package's own modules: the executors are given as util has them.
from reflector_opt.util._dask_pool import dask_cluster  # noqa: E402

__getattr__, _, __all__ = lazy_loader.attach(__name__, submod_attrs=_MODULES)
__all__ += ["dask_cluster"]


def __dir__():
    return list(__all__)
