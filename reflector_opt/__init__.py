"""reflector_opt: design the convex spherical reflector of an optoelectronic shape sensor.

Lengths are in millimetres and angles in degrees at every public boundary; see
docs/conventions.md for the frame and the signs of pitch and roll.
"""

from reflector_opt.design import Design, default_design, load_design
from reflector_opt.model.forward import Response, respond, voltages
from reflector_opt.model.sensors import PRESETS, SensorModel, get_preset
from reflector_opt.util.errors import CollisionError, InputError

__all__ = [
    "PRESETS",
    "CollisionError",
    "Design",
    "InputError",
    "Response",
    "SensorModel",
    "default_design",
    "get_preset",
    "load_design",
    "respond",
    "voltages",
]

__version__ = "0.1.0"
