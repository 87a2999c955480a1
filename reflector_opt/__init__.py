"""reflector_opt: design the convex spherical reflector of an optoelectronic shape sensor.

The main job, each step computed in memory and written only by ``write``::

    import reflector_opt as ro

    run = ro.optimise(sensor="NJL5901R-2", conditions="conditions.toml")
    print(ro.evaluate(run.design, conditions="conditions.toml"))  # its error in use
    ro.export(run.design).write("cad_out/parts")  # printable parts, checked
    calibration = ro.calibrate("data.csv")  # per printed unit, cross-validated
    angles = ro.estimate(calibration, "log.csv").shape  # unit and tip angles

Lengths are in millimetres and angles in degrees at every public boundary; see
docs/conventions.md for the frame and the signs of pitch and roll.
"""

import sys

import lazy_loader

from reflector_opt.util._moved import MovedModules

sys.meta_path.append(MovedModules())

#: The modules that define the public names, and the names each gives; a module is
#: imported the first time one of its names is used.
_MODULES = {
    "model._sensors": ("PRESETS", "SensorModel", "get_preset"),
    "util._errors": ("CollisionError", "InputError"),
    "design._design": ("Design", "load_design"),
    "design._defaults": ("default_design",),
    "workflow": (
        "CalibrateRun",
        "CompareRun",
        "EstimateRun",
        "EvaluateRun",
        "ExportRun",
        "IdentifyRun",
        "OptimiseOptions",
        "OptimiseRun",
        "PlanCalibrationRun",
        "ReportRun",
        "SmallestOptions",
        "SmallestRun",
        "SweepRun",
        "ToleranceRun",
        "calibrate",
        "compare",
        "estimate",
        "evaluate",
        "export",
        "identify",
        "optimise",
        "plan_calibration",
        "smallest",
        "sweep",
    ),
    "model._forward": ("Response", "respond", "voltages"),
}

_exported, __dir__, __all__ = lazy_loader.attach(__name__, submod_attrs=_MODULES)


def __getattr__(name):
    from reflector_opt.workflow._deprecated import DEPRECATED, deprecated_alias

    return deprecated_alias(name) if name in DEPRECATED else _exported(name)


__version__ = "0.1.0"
