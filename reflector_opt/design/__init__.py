"""The design: reflector, sensors, workspace, mechanics, noise, and the printed parts' layout.

Layer 2: imports :mod:`reflector_opt.model` and :mod:`reflector_opt.util`.

* :mod:`~reflector_opt.design._design` — the :class:`Design` and :func:`load_design`;
* :mod:`~reflector_opt.design._components` — its parts: :class:`Reflector`,
  :class:`SensorPlacement`, :class:`Workspace`, :class:`Mechanics`, :class:`Noise`;
* :mod:`~reflector_opt.design._designfile` — the ``design.json`` document (format tag,
  writing a design, reading its parts back);
* :mod:`~reflector_opt.design._validation` — value checks whose messages name the field;
* :mod:`~reflector_opt.design._defaults` — :func:`default_design`, the paper's prototype, and
  :func:`as_design` (a design, its file, or that one);
* :mod:`~reflector_opt.design._parts` — the printed parts' dimensions (CAD parameters);
* :mod:`~reflector_opt.design._layout` — where the printed features go (windows, mounts,
  tendon holes), shared by the optimiser's wall check and the CAD export;
* :mod:`~reflector_opt.design._polar` — regions and directions about O (the layout's polar
  boxes).

The names of the design itself are re-exported here: ``from reflector_opt.design import
Design``.
"""

import lazy_loader

#: The modules that define the public names, and the names each gives; a module is
#: imported the first time one of its names is used.
_MODULES = {
    "_design": ("Design", "load_design"),
    "_components": ("Mechanics", "Noise", "Reflector", "SensorPlacement", "Workspace"),
    "_defaults": ("as_design", "default_design"),
    "_conditions": ("Conditions",),
}

__getattr__, __dir__, __all__ = lazy_loader.attach(__name__, submod_attrs=_MODULES)
