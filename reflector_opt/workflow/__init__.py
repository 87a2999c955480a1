"""The workflows of the command line as library calls: one call makes the run a command makes.

Layer: above :mod:`reflector_opt.report`, below :mod:`reflector_opt.cli`. Each command listed
below parses its options, calls its run and prints what it returns; a notebook or a script
makes the same run, with the same outputs, in one call::

    import reflector_opt as ro

    run = ro.optimise_run(ro.OptimiseOptions(seed=0, pareto=True), out="cad_out")
    run.design  # the optimised Design; run.files lists every file written

* :mod:`~reflector_opt.workflow.options` — the options of an optimisation run and their checks;
* :mod:`~reflector_opt.workflow.optimise` — :func:`optimise_run` (``reflector-opt optimise``),
  its text from :mod:`~reflector_opt.workflow.optimise_text`;
* :mod:`~reflector_opt.workflow.evaluate` — :func:`evaluate_run` (``reflector-opt evaluate``),
  its text from :mod:`~reflector_opt.workflow.evaluate_text`;
* :mod:`~reflector_opt.workflow.report` — :func:`report_run` (``reflector-opt report``);
* :mod:`~reflector_opt.workflow.export` — :func:`export_run` (``reflector-opt export``);
* :mod:`~reflector_opt.workflow.correct` — :func:`correct_run` (``reflector-opt correct``),
  returning a :class:`~reflector_opt.workflow.correctrun.CorrectRun`;
* :mod:`~reflector_opt.workflow.smallest` — :func:`smallest_run` (``reflector-opt smallest``);
* :mod:`~reflector_opt.workflow.compare` — :func:`compare_run` (``reflector-opt compare``);
* :mod:`~reflector_opt.workflow.calibrate` — :func:`calibrate_run` (``reflector-opt calibrate``);
* :mod:`~reflector_opt.workflow.estimate` — :func:`estimate_run` (``reflector-opt estimate``);
* :mod:`~reflector_opt.workflow.fit_sensor` — :func:`fit_sensor_run` (``reflector-opt
  fit-sensor``);
* :mod:`~reflector_opt.workflow.identify` — :func:`identify_run` (``reflector-opt identify``);
* :mod:`~reflector_opt.workflow.plan_calibration` — :func:`plan_calibration_run`
  (``reflector-opt plan-calibration``), its text from :mod:`~reflector_opt.workflow.plan_text`;
* :mod:`~reflector_opt.workflow.tolerance` — :func:`tolerance_run` (``reflector-opt
  tolerance``) and :mod:`~reflector_opt.workflow.sweep` — :func:`sweep_run` (``reflector-opt
  sweep``), their text from :mod:`~reflector_opt.workflow.tolerance_text`;
* :mod:`~reflector_opt.workflow.runs` — what they return: the results, the files written, a
  short ``repr``, a notebook display and the JSON summary of ``--json``.
"""

import lazy_loader

#: The modules that define the public names, and the names each gives; a module is
#: imported the first time one of its names is used.
_MODULES = {
    "runs": ("EvaluateRun", "OptimiseRun", "ReportRun"),
    "correctrun": ("CorrectRun",),
    "correct": ("correct_run",),
    "options": ("OptimiseOptions",),
    "evaluate": ("evaluate_run",),
    "optimise": ("optimise_run",),
    "report": ("report_run",),
    "export": ("ExportRun", "export_run"),
    "smallest": ("SmallestOptions", "SmallestRun", "smallest_run"),
    "compare": ("CompareRun", "compare_run"),
    "calibrate": ("CalibrateRun", "calibrate_run"),
    "estimate": ("EstimateRun", "estimate_run"),
    "fit_sensor": ("FitSensorRun", "fit_sensor_run"),
    "identify": ("IdentifyRun", "identify_run"),
    "plan_calibration": ("PlanCalibrationRun", "plan_calibration_run"),
    "tolerance": ("ToleranceRun", "tolerance_run"),
    "sweep": ("SweepRun", "sweep_run"),
}

__getattr__, __dir__, __all__ = lazy_loader.attach(__name__, submod_attrs=_MODULES)
