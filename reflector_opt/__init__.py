"""reflector_opt: design the convex spherical reflector of an optoelectronic shape sensor.

Lengths are in millimetres and angles in degrees at every public boundary; see
docs/conventions.md for the frame and the signs of pitch and roll.
"""

from reflector_opt.util.lazy import lazy_exports

#: Each public name and the module that defines it, imported on first use.
_SOURCES = {
    "PRESETS": "reflector_opt.model.sensors",
    "CollisionError": "reflector_opt.util.errors",
    "Design": "reflector_opt.design",
    "EvaluateRun": "reflector_opt.workflow",
    "InputError": "reflector_opt.util.errors",
    "OptimiseOptions": "reflector_opt.workflow",
    "OptimiseRun": "reflector_opt.workflow",
    "ReportRun": "reflector_opt.workflow",
    "Response": "reflector_opt.model.forward",
    "SensorModel": "reflector_opt.model.sensors",
    "default_design": "reflector_opt.design",
    "evaluate_run": "reflector_opt.workflow",
    "get_preset": "reflector_opt.model.sensors",
    "load_design": "reflector_opt.design",
    "optimise_run": "reflector_opt.workflow",
    "report_run": "reflector_opt.workflow",
    "respond": "reflector_opt.model.forward",
    "voltages": "reflector_opt.model.forward",
}

__all__ = list(_SOURCES)
__getattr__, __dir__ = lazy_exports(__name__, _SOURCES)

__version__ = "0.1.0"
