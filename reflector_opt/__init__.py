"""reflector_opt: design the convex spherical reflector of an optoelectronic shape sensor.

Lengths are in millimetres and angles in degrees at every public boundary; see
docs/conventions.md for the frame and the signs of pitch and roll.
"""

import lazy_loader

#: The modules that define the public names, and the names each gives; a module is
#: imported the first time one of its names is used.
_MODULES = {
    "model.sensors": ("PRESETS", "SensorModel", "get_preset"),
    "util.errors": ("CollisionError", "InputError"),
    "design.design": ("Design", "load_design"),
    "design.defaults": ("default_design",),
    "workflow.options": ("OptimiseOptions",),
    "workflow.optimise": ("optimise_run",),
    "workflow.evaluate": ("evaluate_run",),
    "workflow.report": ("report_run",),
    "workflow.runs": ("EvaluateRun", "OptimiseRun", "ReportRun"),
    "model.forward": ("Response", "respond", "voltages"),
}

__getattr__, __dir__, __all__ = lazy_loader.attach(__name__, submod_attrs=_MODULES)

__version__ = "0.1.0"
