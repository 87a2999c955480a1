"""The sensor on the robot (docs/robot.md): the device protocol, the calibration
as C and a virtual device.

Layer: above :mod:`reflector_opt.calibration`; imports it, :mod:`reflector_opt.model`,
:mod:`reflector_opt.design` and :mod:`reflector_opt.util`.

* :mod:`~reflector_opt.robot._protocol` — frames, their text and binary forms, the
  incremental decoder that counts each fault, and the transports (serial, UDP, file or pipe);
* :mod:`~reflector_opt.robot._firmware` — a calibration as a C99 header, float and fixed point
  (``reflector-opt firmware``);
* :mod:`~reflector_opt.robot._virtual` — built units sending frames at a rate along a
  trajectory, on an injectable clock, for tests, demos and work without hardware;
* :mod:`~reflector_opt.robot._stream` — frames to each unit's pitch and roll with a 1σ, and the
  tip (``reflector-opt stream``);
* :mod:`~reflector_opt.robot._mcap` — those as an MCAP log with ROS 2 schemas;
* :mod:`~reflector_opt.robot._record` — a calibration run live against an angle reference
  (``reflector-opt record``).

Two names are public, :class:`~reflector_opt.robot._protocol.Protocol` (its ``encode`` and
``decoder``) and :class:`~reflector_opt.robot._virtual.VirtualDevice`; the rest is reached
through them or by its module path.
"""

import lazy_loader

#: The modules that define the public names, and the names each gives; a module is
#: imported the first time one of its names is used.
_MODULES = {"_protocol": ("Protocol",), "_virtual": ("VirtualDevice",)}

__getattr__, __dir__, __all__ = lazy_loader.attach(__name__, submod_attrs=_MODULES)
