"""The workflows of the command line as library calls: each computes its run in memory, and
the run's ``write`` writes what the command writes.

Layer: above :mod:`reflector_opt.report`, below :mod:`reflector_opt.cli`. Each command parses
its options, makes its run, writes it into its ``-o`` and prints it; a notebook or a script
makes the same run, with the same outputs, in one call, and writes it only if asked::

    import reflector_opt as ro

    run = ro.optimise(seed=0, pareto=True)
    run.design  # the optimised Design, nothing written yet
    run = run.write("cad_out",)  # run.files lists every file written

* :mod:`~reflector_opt.workflow._options` — the options of an optimisation run and their checks;
* :mod:`~reflector_opt.workflow._optimise` — :func:`optimise` (``reflector-opt optimise``),
  its text from :mod:`~reflector_opt.workflow._optimise_text`;
* :mod:`~reflector_opt.workflow._evaluate` — :func:`evaluate` (``reflector-opt evaluate``),
  its text from :mod:`~reflector_opt.workflow._evaluate_text`;
* :mod:`~reflector_opt.workflow._report` — :func:`report` (``reflector-opt report``);
* :mod:`~reflector_opt.workflow._export` — :func:`export` (``reflector-opt export``);
* :mod:`~reflector_opt.workflow._correct` — :func:`correct` (``reflector-opt correct``),
  returning a :class:`~reflector_opt.workflow._correctrun.CorrectRun`;
* :mod:`~reflector_opt.workflow._smallest` — :func:`smallest` (``reflector-opt smallest``);
* :mod:`~reflector_opt.workflow._compare` — :func:`compare` (``reflector-opt compare``);
* :mod:`~reflector_opt.workflow._calibrate` — :func:`calibrate` (``reflector-opt calibrate``);
* :mod:`~reflector_opt.workflow._estimate` — :func:`estimate` (``reflector-opt estimate``);
* :mod:`~reflector_opt.workflow._fit_sensor` — :func:`fit_sensor` (``reflector-opt
  fit-sensor``);
* :mod:`~reflector_opt.workflow._identify` — :func:`identify` (``reflector-opt identify``);
* :mod:`~reflector_opt.workflow._plan_calibration` — :func:`plan_calibration`
  (``reflector-opt plan-calibration``), its text from :mod:`~reflector_opt.workflow._plan_text`;
* :mod:`~reflector_opt.workflow._tolerance` — :func:`tolerance` (``reflector-opt
  tolerance``) and :mod:`~reflector_opt.workflow._sweep` — :func:`sweep` (``reflector-opt
  sweep``), their text from :mod:`~reflector_opt.workflow._tolerance_text`;
* :mod:`~reflector_opt.workflow._runs` — what they return: the results, ``write``, a short
  ``repr``, a notebook display and the JSON summary of ``--json``.

The earlier names (``optimise_run``, ``evaluate_run``, … with an output argument) remain for
one release as deprecated aliases.
"""

import lazy_loader

#: The modules that define the public names, and the names each gives; a module is
#: imported the first time one of its names is used.
_MODULES = {
    "_runs": ("EvaluateRun", "ReportRun"),
    "_correctrun": ("CorrectRun",),
    "_correct": ("correct",),
    "_options": ("OptimiseOptions",),
    "_evaluate": ("evaluate",),
    "_optimise": ("OptimiseRun", "optimise"),
    "_report": ("report",),
    "_export": ("ExportRun", "export"),
    "_smallest": ("SmallestOptions", "SmallestRun", "smallest"),
    "_compare": ("CompareRun", "compare"),
    "_calibrate": ("CalibrateRun", "calibrate"),
    "_estimate": ("EstimateRun", "estimate"),
    "_fit_sensor": ("FitSensorRun", "fit_sensor"),
    "_identify": ("IdentifyRun", "identify"),
    "_plan_calibration": ("PlanCalibrationRun", "plan_calibration"),
    "_tolerance": ("ToleranceRun", "tolerance"),
    "_sweep": ("SweepRun", "sweep"),
}

_exported, __dir__, __all__ = lazy_loader.attach(__name__, submod_attrs=_MODULES)


def __getattr__(name):
    from reflector_opt.workflow._deprecated import DEPRECATED, deprecated_alias

    return deprecated_alias(name) if name in DEPRECATED else _exported(name)
